/* Node-to-quad projection and the kinematic contact force through the C
 * ABI, checked against geometry:
 *  1. a node above a flat unit square projects to its foot, gap = height;
 *  2. on a warped quad the projection is the closest point: no point of a
 *     fine (ξ, η) grid on the face is nearer (brute force), the normal is
 *     unit length and the weights sum to one;
 *  3. the contact force balances (slave + Σ corners = 0) and, frictionless
 *     on a flat face with w = 1, moves the node and the face so that the
 *     predicted gap closes to round-off after x ← x̃ + Δt² f / m;
 *  4. with friction the tangential force stays on the Coulomb cap μ F_n.
 * Exit status 0 if all hold. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "granbed.h"

static int failures = 0;

static void check(const char *what, int ok) {
    if (!ok) { fprintf(stderr, "FAIL %s\n", what); failures++; }
}

static void bilinear(const double q[12], double xi, double eta, double x[3]) {
    const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int a = 0; a < 3; a++) {
        x[a] = 0;
        for (int i = 0; i < 4; i++) x[a] += 0.25 * (1 + s[i][0] * xi) * (1 + s[i][1] * eta) * q[3 * i + a];
    }
}

static double dist2(const double a[3], const double b[3]) {
    double d = 0;
    for (int k = 0; k < 3; k++) d += (a[k] - b[k]) * (a[k] - b[k]);
    return d;
}

int main(void) {
    /* 1. Flat unit square at z = 0 (corners counter-clockwise from +z). */
    const double flat[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const double p1[3] = {0.3, 0.6, 0.25};
    GranbedQuadProjection q;
    check("flat projection", granbed_project_node_on_quad(p1, flat, &q) == GRANBED_OK);
    printf("project_quad: flat: xi %.17g eta %.17g gap %.17g normal (%g %g %g)\n", q.xi, q.eta, q.gap,
           q.normal[0], q.normal[1], q.normal[2]);
    check("flat foot", fabs(q.xi - (-0.4)) < 1e-15 && fabs(q.eta - 0.2) < 1e-15);
    check("flat gap", fabs(q.gap - 0.25) < 1e-15 && q.normal[2] == 1.0 && q.inside == 1);

    /* 2. A warped quad: brute-force closest point on a 2001² grid. */
    const double warped[12] = {0, 0, 0.1, 1.2, 0, -0.05, 1, 0.9, 0.2, -0.1, 1, -0.1};
    const double p2[3] = {0.45, 0.4, 0.3};
    check("warped projection", granbed_project_node_on_quad(p2, warped, &q) == GRANBED_OK);
    double best = INFINITY;
    for (int i = 0; i <= 2000; i++)
        for (int j = 0; j <= 2000; j++) {
            double x[3];
            bilinear(warped, -1 + i / 1000.0, -1 + j / 1000.0, x);
            double d = dist2(x, p2);
            if (d < best) best = d;
        }
    double d_proj = dist2(q.point, p2);
    double wsum = q.weights[0] + q.weights[1] + q.weights[2] + q.weights[3];
    double nn = q.normal[0] * q.normal[0] + q.normal[1] * q.normal[1] + q.normal[2] * q.normal[2];
    printf("project_quad: warped: distance %.12g, best of the grid %.12g\n", sqrt(d_proj), sqrt(best));
    check("closest point", d_proj <= best * (1 + 1e-12));
    check("unit normal and weights", fabs(nn - 1) < 1e-14 && fabs(wsum - 1) < 1e-14);
    check("gap = distance in front of the face", fabs(fabs(q.gap) - sqrt(d_proj)) < 1e-12 && q.gap > 0);

    /* 3. A node 1 µm behind the flat face after its predictor step. */
    const double dt2 = 1e-12;
    GranbedNodeFace c;
    memset(&c, 0, sizeof c);
    c.slave_mass = 2e-9;
    const double xs_n[3] = {0.3, 0.6, 0.5e-6}, xs_pred[3] = {0.3, 0.6, -1e-6};
    memcpy(c.slave_x_n, xs_n, sizeof xs_n);
    memcpy(c.slave_x_pred, xs_pred, sizeof xs_pred);
    for (int i = 0; i < 4; i++) {
        c.master_mass[i] = 1e-9 * (1 + i);
        memcpy(c.master_x_n[i], flat + 3 * i, 3 * sizeof(double));
        memcpy(c.master_x_pred[i], flat + 3 * i, 3 * sizeof(double));
    }
    check("contact projection", granbed_project_node_on_quad(c.slave_x_pred, flat, &q) == GRANBED_OK);
    memcpy(c.weights, q.weights, sizeof q.weights);
    memcpy(c.normal, q.normal, sizeof q.normal);
    c.gap = q.gap;
    GranbedNodeFaceForce f;
    check("force", granbed_node_face_force(&c, 1.0, 0.0, dt2, &f) == GRANBED_OK);
    double sum[3] = {f.slave[0], f.slave[1], f.slave[2]};
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++) sum[a] += f.master[i][a];
    check("momentum balance", fabs(sum[0]) + fabs(sum[1]) + fabs(sum[2]) <= 1e-15 * f.normal);
    double xs[3], xm[12];
    for (int a = 0; a < 3; a++) xs[a] = c.slave_x_pred[a] + dt2 * f.slave[a] / c.slave_mass;
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++) xm[3 * i + a] = c.master_x_pred[i][a] + dt2 * f.master[i][a] / c.master_mass[i];
    double contact_point[3] = {0, 0, 0};
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++) contact_point[a] += c.weights[i] * xm[3 * i + a];
    double gap_after = xs[2] - contact_point[2];
    printf("project_quad: gap before %.3g m, after the corrector %.3g m, F_n %.6g N\n", c.gap, gap_after, f.normal);
    check("gap closed", fabs(gap_after) < 1e-12 * fabs(c.gap) + 1e-21);

    /* 4. Sliding: the node also moves 5 µm sideways; μ = 0.1 caps friction. */
    c.slave_x_pred[0] += 5e-6;
    check("sliding force", granbed_node_face_force(&c, 1.0, 0.1, dt2, &f) == GRANBED_OK);
    double ft = sqrt(f.friction[0] * f.friction[0] + f.friction[1] * f.friction[1] + f.friction[2] * f.friction[2]);
    printf("project_quad: sliding: |F_t| %.6g N = %.6g mu F_n, slipping %d\n", ft, ft / f.normal, f.slipping);
    check("Coulomb cap", f.slipping == 1 && fabs(ft - 0.1 * f.normal) < 1e-12 * f.normal && f.friction[0] < 0);

    printf("project_quad: %s\n", failures ? "FAILED" : "all checks hold");
    return failures ? 1 : 0;
}
