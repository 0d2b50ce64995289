/* Bad input through the C ABI: every case must return the documented
 * status code (never crash), and a rejected material parameter must be
 * named with its value and allowed range. Exit status 0 if all hold. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "granbed.h"

static int failures = 0;

static void expect(const char *what, int32_t got, int32_t want) {
    if (got != want) {
        fprintf(stderr, "FAIL %s: status %d (%s), expected %d (%s)\n", what, got,
                granbed_status_message(got), want, granbed_status_message(want));
        failures++;
    }
}

int main(void) {
    GranbedMaterialParams p;
    expect("preset B2", granbed_material_preset("B2", &p), GRANBED_OK);
    expect("preset lower case", granbed_material_preset("c3", &p), GRANBED_OK);
    expect("unknown type", granbed_material_preset("D4", &p), GRANBED_ERR_INVALID_ARGUMENT);
    expect("long name", granbed_material_preset("B22222", &p), GRANBED_ERR_INVALID_ARGUMENT);
    expect("NULL name", granbed_material_preset(NULL, &p), GRANBED_ERR_NULL_POINTER);
    expect("NULL out", granbed_material_preset("B2", NULL), GRANBED_ERR_NULL_POINTER);
    expect("check B2", granbed_material_check(&p, NULL), GRANBED_OK);

    /* A bad Poisson ratio: named, with value and range. */
    GranbedMaterialParams bad = p;
    bad.poisson_ratio = 0.6;
    GranbedParamError e;
    memset(&e, 0, sizeof e);
    expect("nu = 0.6", granbed_material_check(&bad, &e), GRANBED_ERR_INVALID_PARAMETER);
    printf("errors: invalid material parameter `%s` = %g: allowed range is %s\n", e.field, e.value, e.allowed);
    if (strcmp(e.field, "poisson_ratio") != 0 || e.value != 0.6 || strlen(e.allowed) == 0) {
        fprintf(stderr, "FAIL: the error does not name poisson_ratio = 0.6 with a range\n");
        failures++;
    }
    bad = p;
    bad.youngs_modulus_pa = NAN;
    expect("E = NaN", granbed_material_check(&bad, &e), GRANBED_ERR_INVALID_PARAMETER);
    if (strcmp(e.field, "youngs_modulus_pa") != 0) { fprintf(stderr, "FAIL: E not named\n"); failures++; }

    /* The batch update: argument errors write nothing; point errors are per point. */
    double f[3 * 9] = {1, 0, 0, 0, 1, 0, 0, 0, 0.99, /* fine */
                       1, 0, 0, 0, 1, 0, 0, 0, -0.5, /* inverted */
                       1, 0, 0, 0, 1, 0, 0, 0, NAN}; /* not finite */
    double cp[3 * 6], tau[3 * 6];
    int32_t st[3];
    granbed_state_init(3, cp);
    expect("stress measure 7", granbed_update_points(&p, 1, 3, f, cp, 7, tau, NULL, st),
           GRANBED_ERR_INVALID_ARGUMENT);
    expect("volume_fix 2", granbed_update_points(&p, 2, 3, f, cp, 0, tau, NULL, st), GRANBED_ERR_INVALID_ARGUMENT);
    expect("NULL f", granbed_update_points(&p, 1, 3, NULL, cp, 0, tau, NULL, st), GRANBED_ERR_NULL_POINTER);
    expect("bad material", granbed_update_points(&bad, 1, 3, f, cp, 0, tau, NULL, st),
           GRANBED_ERR_INVALID_PARAMETER);
    expect("huge n", granbed_update_points(&p, 1, (size_t)-1 / 4, f, cp, 0, tau, NULL, st), GRANBED_ERR_SIZE);
    expect("zero points", granbed_update_points(&p, 1, 0, NULL, NULL, 0, NULL, NULL, NULL), GRANBED_OK);
    expect("batch with bad points", granbed_update_points(&p, 1, 3, f, cp, 1, tau, NULL, st),
           GRANBED_ERR_POINT_FAILED);
    expect("point 0", st[0], GRANBED_OK);
    expect("point 1 inverted", st[1], GRANBED_ERR_INVERTED);
    expect("point 2 NaN", st[2], GRANBED_ERR_NON_FINITE);
    if (!(tau[2] < 0.0) || cp[6] != 1.0 || tau[6 + 2] != 0.0) {
        fprintf(stderr, "FAIL: the good point was not updated or a failed one was touched\n");
        failures++;
    }

    /* A corrupt state. */
    double corrupt[6] = {-1, 1, 1, 0, 0, 0};
    expect("corrupt state", granbed_update_points(&p, 1, 1, f, corrupt, 0, tau, NULL, st), GRANBED_ERR_POINT_FAILED);
    expect("corrupt state code", st[0], GRANBED_ERR_INVALID_STATE);
    /* det > 0, but two negative eigenvalues: not positive definite. */
    double indefinite[6] = {-1, -1, 1, 0, 0, 0};
    expect("indefinite state", granbed_update_points(&p, 1, 1, f, indefinite, 0, tau, NULL, st), GRANBED_ERR_POINT_FAILED);
    expect("indefinite state code", st[0], GRANBED_ERR_INVALID_STATE);

    /* Elements and contact. */
    double flat[24] = {0};
    double ref[GRANBED_HEX_REFERENCE_LEN];
    expect("degenerate hex", granbed_hex_reference(1, flat, ref, st), GRANBED_ERR_POINT_FAILED);
    expect("degenerate hex code", st[0], GRANBED_ERR_DEGENERATE);
    double pt[3] = {0, 0, 1}, quad[12] = {0};
    GranbedQuadProjection q;
    expect("degenerate quad", granbed_project_node_on_quad(pt, quad, &q), GRANBED_ERR_DEGENERATE);
    GranbedNodeFace c;
    memset(&c, 0, sizeof c);
    GranbedNodeFaceForce out;
    expect("zero masses", granbed_node_face_force(&c, 1.0, 0.1, 1e-12, &out), GRANBED_ERR_INVALID_ARGUMENT);
    expect("NULL constraint", granbed_node_face_force(NULL, 1.0, 0.1, 1e-12, &out), GRANBED_ERR_NULL_POINTER);
    /* A valid constraint: a node 1 µm behind the face z = 0. */
    c.slave_mass = 1e-9;
    for (int i = 0; i < 4; i++) c.master_mass[i] = 1e-9;
    c.weights[0] = 1;
    c.normal[2] = 1;
    c.gap = -1e-6;
    c.slave_x_pred[2] = -1e-6;
    expect("penetrating constraint", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out), GRANBED_OK);
    if (!(out.normal > 0)) {
        fprintf(stderr, "FAIL: a penetrating constraint gives no push (F_n = %g)\n", out.normal);
        failures++;
    }
    /* A non-negative gap is no contact: zero force (it was a pull and NaN). */
    c.gap = 1e-3;
    expect("positive gap", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out), GRANBED_OK);
    if (out.normal != 0 || out.slave[0] != 0 || out.slave[1] != 0 || out.slave[2] != 0) {
        fprintf(stderr, "FAIL: positive gap: F_n = %g, slave force (%g, %g, %g), expected 0\n", out.normal,
                out.slave[0], out.slave[1], out.slave[2]);
        failures++;
    }
    c.gap = -1e-6;
    c.normal[2] = 0;
    expect("zero normal", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out), GRANBED_ERR_INVALID_ARGUMENT);
    c.normal[2] = 1e6;
    expect("normal of length 1e6", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out), GRANBED_ERR_INVALID_ARGUMENT);
    c.normal[2] = 1 + 0.5 * GRANBED_UNIT_TOLERANCE;
    expect("normal within tolerance", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out), GRANBED_OK);
    c.normal[2] = 1;
    c.master_mass[1] = 0; /* its weight is 0 */
    expect("zero master mass, weight 0", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out),
           GRANBED_ERR_INVALID_ARGUMENT);
    c.master_mass[1] = 1e-9;
    expect("NaN friction", granbed_node_face_force(&c, 1.0, NAN, 1e-16, &out), GRANBED_ERR_INVALID_ARGUMENT);
    expect("dt^2 = 0", granbed_node_face_force(&c, 1.0, 0.3, 0.0, &out), GRANBED_ERR_INVALID_ARGUMENT);
    expect("dt^2 = inf", granbed_node_face_force(&c, 1.0, 0.3, INFINITY, &out), GRANBED_ERR_INVALID_ARGUMENT);
    c.weights[1] = 0.5;
    expect("weights summing to 1.5", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out),
           GRANBED_ERR_INVALID_ARGUMENT);
    c.weights[1] = 0;
    c.weights[0] = 2;
    c.weights[1] = -1;
    expect("weights off the face", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out),
           GRANBED_ERR_INVALID_ARGUMENT);
    c.weights[0] = 1;
    c.weights[1] = 0;
    c.gap = -1e300;
    expect("overflowing force", granbed_node_face_force(&c, 1.0, 0.3, 1e-300, &out), GRANBED_ERR_NON_FINITE);
    c.gap = NAN;
    expect("NaN gap", granbed_node_face_force(&c, 1.0, 0.3, 1e-16, &out), GRANBED_ERR_NON_FINITE);

    /* A corrupt hex reference record fails its element, not silently. */
    {
        static const double cube[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
        double good[GRANBED_HEX_REFERENCE_LEN], r[GRANBED_HEX_REFERENCE_LEN], cp[6], fe[24], x[24];
        int32_t est[1];
        expect("unit cube reference", granbed_hex_reference(1, cube, good, est), GRANBED_OK);
        memcpy(x, cube, sizeof x);
        x[18] += 0.01;
        /* V0 NaN and negative, the hourglass factor NaN and negative, a
         * gamma0 entry infinite, a node volume 0. */
        const int at[6] = {0, 0, 57, 57, 30, 60};
        const double value[6] = {NAN, -1.0, NAN, -1.0, INFINITY, 0.0};
        for (int k = 0; k < 6; k++) {
            memcpy(r, good, sizeof r);
            r[at[k]] = value[k];
            granbed_state_init(1, cp);
            char what[64];
            snprintf(what, sizeof what, "corrupt reference [%d] = %g", at[k], value[k]);
            expect(what, granbed_hex_forces(&p, 1, 0.05, 1, r, x, cp, fe, NULL, NULL, est),
                   GRANBED_ERR_POINT_FAILED);
            expect(what, est[0], GRANBED_ERR_INVALID_ARGUMENT);
        }
        granbed_state_init(1, cp);
        expect("good reference", granbed_hex_forces(&p, 1, 0.05, 1, good, x, cp, fe, NULL, NULL, est), GRANBED_OK);
        /* A state with det > 0 that is not positive definite. */
        const double indefinite[6] = {-1, -1, 1, 0, 0, 0};
        memcpy(cp, indefinite, sizeof cp);
        expect("indefinite element state", granbed_hex_forces(&p, 1, 0.05, 1, good, x, cp, fe, NULL, NULL, est),
               GRANBED_ERR_POINT_FAILED);
        expect("indefinite element state code", est[0], GRANBED_ERR_INVALID_STATE);
    }
    expect("vumat nstatev 5", granbed_vumat(1, 5, 8, NULL, NULL, NULL, NULL, NULL, NULL), GRANBED_ERR_INVALID_ARGUMENT);
    if (strcmp(granbed_status_message(12345), "unknown status code") != 0) {
        fprintf(stderr, "FAIL: unknown code message\n");
        failures++;
    }
    printf("errors: %s (library %s)\n", failures ? "FAILED" : "all cases gave the documented status",
           granbed_version());
    return failures ? 1 : 0;
}
