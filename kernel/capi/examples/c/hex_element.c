/* The one-point hex through the C ABI, checked against mechanics:
 *  1. a unit cube under a homogeneous F: the element's Kirchhoff stress is
 *     the material point's (granbed_update_points with the same F) to
 *     round-off, the nodal forces sum to zero and are V0 τ F^-T B0_I, and a
 *     homogeneous field excites no hourglass force;
 *  2. a rigid rotation of the deformed cube rotates the forces with it
 *     (objectivity);
 *  3. two elements in one batch, one inverted: per-element status codes,
 *     the good one still computed;
 *  4. the derived constants (granbed_material_derived): a small uniaxial
 *     strain ε gives τ_xx = (λ + 2μ)ε and τ_yy = λε to 1e-6, c_d² ρ0 is
 *     the P-wave modulus, ρ0 = η0 ρ_true; bad parameters name the field;
 *  5. the hourglass energy: none in a homogeneous field; for a pure
 *     hourglass mode (u_x ∝ ξηζ, F̄ = 1, so τ = 0) the forces are the
 *     hourglass spring's and its energy is ½ Σ f·u.
 * Exit status 0 if all hold. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "granbed.h"

static int failures = 0;
static void check(const char *what, int ok) {
    if (!ok) { fprintf(stderr, "FAIL %s\n", what); failures++; }
}

/* Node I of the unit cube in the trilinear order. */
static const double CUBE[8][3] = {{0, 0, 0}, {1e-3, 0, 0}, {1e-3, 1e-3, 0}, {0, 1e-3, 0},
                                  {0, 0, 1e-3}, {1e-3, 0, 1e-3}, {1e-3, 1e-3, 1e-3}, {0, 1e-3, 1e-3}};

static void apply(const double f[9], const double x[24], double out[24]) {
    for (int i = 0; i < 8; i++)
        for (int a = 0; a < 3; a++)
            out[3 * i + a] = f[3 * a] * x[3 * i] + f[3 * a + 1] * x[3 * i + 1] + f[3 * a + 2] * x[3 * i + 2];
}

int main(void) {
    GranbedMaterialParams p;
    granbed_material_preset("B2", &p);
    double xref[24];
    memcpy(xref, CUBE, sizeof xref);
    double ref[GRANBED_HEX_REFERENCE_LEN];
    int32_t st[2];
    check("reference", granbed_hex_reference(1, xref, ref, st) == GRANBED_OK && st[0] == GRANBED_OK);
    check("volume", fabs(ref[0] - 1e-9) < 1e-24);

    /* 4. The derived constants against the element's small-strain response. */
    {
        GranbedMaterialDerived d;
        GranbedParamError e;
        check("derived", granbed_material_derived(&p, &d, &e) == GRANBED_OK);
        const double eps = 1e-7, Fs[9] = {1 + eps, 0, 0, 0, 1, 0, 0, 0, 1};
        double xs[24], cps[6], fs[24], taus[6];
        apply(Fs, xref, xs);
        granbed_state_init(1, cps);
        check("small strain", granbed_hex_forces(&p, 1, GRANBED_DEFAULT_HOURGLASS_KAPPA, 1, ref, xs, cps, fs, taus,
                                                 NULL, st) == GRANBED_OK);
        check("tau_xx = (lambda + 2 mu) eps", fabs(taus[0] / (eps * d.p_wave_pa) - 1) < 1e-6);
        check("tau_yy = lambda eps", fabs(taus[1] / (eps * d.lambda_pa) - 1) < 1e-6);
        check("p-wave = lambda + 2 mu", fabs(d.p_wave_pa - d.lambda_pa - 2 * d.mu_pa) <= 1e-12 * d.p_wave_pa);
        check("bulk = lambda + 2 mu / 3", fabs(d.bulk_pa - d.lambda_pa - 2 * d.mu_pa / 3) <= 1e-12 * d.bulk_pa);
        check("rho0 = eta0 rho_true", fabs(d.density0_kg_m3 - p.eta0 * p.true_density_kg_m3) <= 1e-12 * d.density0_kg_m3);
        check("c_d^2 rho0 = p-wave",
              fabs(d.wave_speed_m_s * d.wave_speed_m_s * d.density0_kg_m3 / d.p_wave_pa - 1) < 1e-12);
        GranbedMaterialParams bad = p;
        bad.poisson_ratio = 0.5;
        check("derived of bad parameters", granbed_material_derived(&bad, &d, &e) == GRANBED_ERR_INVALID_PARAMETER &&
                                               strcmp(e.field, "poisson_ratio") == 0);
        check("derived, NULL out", granbed_material_derived(&p, NULL, NULL) == GRANBED_ERR_NULL_POINTER);
    }

    /* 1. Homogeneous compression with shear (plastic for B2). */
    const double F[9] = {1.01, 0.02, 0, 0, 0.99, 0.01, 0, 0, 0.9};
    double x[24], cp[6], cp_point[6], f[24], tau[6], tau_point[6];
    apply(F, xref, x);
    granbed_state_init(1, cp);
    granbed_state_init(1, cp_point);
    GranbedPointInfo info, info_point;
    check("forces", granbed_hex_forces(&p, 1, GRANBED_DEFAULT_HOURGLASS_KAPPA, 1, ref, x, cp, f, tau, &info, st) == GRANBED_OK);
    check("point", granbed_update_points(&p, 1, 1, F, cp_point, GRANBED_STRESS_KIRCHHOFF, tau_point, &info_point, st) == GRANBED_OK);
    double dtau = 0, tau_scale = 0;
    for (int c = 0; c < 6; c++) {
        dtau = fmax(dtau, fabs(tau[c] - tau_point[c]));
        tau_scale = fmax(tau_scale, fabs(tau_point[c]));
    }
    printf("hex_element: tau_zz element %.12g Pa, point %.12g Pa, plastic %d/%d\n", tau[2], tau_point[2],
           info.plastic, info_point.plastic);
    check("element stress = point stress", dtau <= 1e-9 * tau_scale && info.plastic == 1);
    check("no hourglass energy in a homogeneous field", fabs(info.hourglass_energy) <= 1e-30);
    check("a point has no hourglass energy", info_point.hourglass_energy == 0);
    double sum[3] = {0, 0, 0}, fmax_abs = 0;
    for (int i = 0; i < 8; i++)
        for (int a = 0; a < 3; a++) { sum[a] += f[3 * i + a]; fmax_abs = fmax(fmax_abs, fabs(f[3 * i + a])); }
    check("forces balance", fabs(sum[0]) + fabs(sum[1]) + fabs(sum[2]) <= 1e-12 * fmax_abs);
    /* The top face (nodes 4-7) carries P_zz times the reference area A0 = 1e-6 m² (f_I = V0 P B0_I with
     * B0_I,z = 1/(4L) on the top; no hourglass force in a homogeneous field). With P = τ F^-T and F
     * upper triangular, row z of F^-1 is (0, 0, 1/F33), so P_zz = τ_zz / F33. */
    double top = f[3 * 4 + 2] + f[3 * 5 + 2] + f[3 * 6 + 2] + f[3 * 7 + 2];
    double expect_top = tau[2] / F[8] * 1e-6;
    printf("hex_element: top-face axial force %.12g N, P_zz A0 %.12g N\n", top, expect_top);
    check("top face force = P A0", fabs(top - expect_top) <= 1e-9 * fabs(expect_top));

    /* 2. Objectivity: rotate the deformed element by 30° about z. */
    const double pi = acos(-1.0), c30 = cos(pi / 6), s30 = sin(pi / 6);
    const double R[9] = {c30, -s30, 0, s30, c30, 0, 0, 0, 1};
    double xr[24], fr[24], cpr[6];
    apply(R, x, xr);
    granbed_state_init(1, cpr);
    check("rotated", granbed_hex_forces(&p, 1, GRANBED_DEFAULT_HOURGLASS_KAPPA, 1, ref, xr, cpr, fr, NULL, NULL, st) == GRANBED_OK);
    double err = 0;
    for (int i = 0; i < 8; i++) {
        double rf[3];
        for (int a = 0; a < 3; a++) rf[a] = R[3 * a] * f[3 * i] + R[3 * a + 1] * f[3 * i + 1] + R[3 * a + 2] * f[3 * i + 2];
        for (int a = 0; a < 3; a++) err = fmax(err, fabs(rf[a] - fr[3 * i + a]));
    }
    printf("hex_element: objectivity error %.3g N of %.3g N\n", err, fmax_abs);
    check("objective", err <= 1e-9 * fmax_abs);

    /* 3. A batch of two, the second inverted (top face pushed below the bottom). */
    double refs[2 * GRANBED_HEX_REFERENCE_LEN], xs[48], cps[12], fs[48];
    memcpy(refs, ref, sizeof ref);
    memcpy(refs + GRANBED_HEX_REFERENCE_LEN, ref, sizeof ref);
    memcpy(xs, x, sizeof x);
    memcpy(xs + 24, xref, sizeof xref);
    for (int i = 4; i < 8; i++) xs[24 + 3 * i + 2] = -1e-3;
    granbed_state_init(2, cps);
    check("batch", granbed_hex_forces(&p, 1, 0.05, 2, refs, xs, cps, fs, NULL, NULL, st) == GRANBED_ERR_POINT_FAILED);
    check("batch codes", st[0] == GRANBED_OK && st[1] == GRANBED_ERR_INVERTED);
    check("good element computed", memcmp(fs, f, sizeof f) == 0);

    /* 5. A pure hourglass mode: u_x = a ξηζ at the corners (a = 1 nm). */
    {
        const double a = 1e-9;
        double xh[24], cph[6], fh[24], work = 0;
        memcpy(xh, xref, sizeof xh);
        for (int i = 0; i < 8; i++) {
            const double xi = CUBE[i][0] > 0 ? 1 : -1, eta = CUBE[i][1] > 0 ? 1 : -1, zeta = CUBE[i][2] > 0 ? 1 : -1;
            xh[3 * i] += a * xi * eta * zeta;
        }
        granbed_state_init(1, cph);
        GranbedPointInfo ih;
        check("hourglass mode", granbed_hex_forces(&p, 1, GRANBED_DEFAULT_HOURGLASS_KAPPA, 1, ref, xh, cph, fh, NULL, &ih,
                                                   st) == GRANBED_OK);
        for (int i = 0; i < 24; i++) work += 0.5 * fh[i] * (xh[i] - xref[i]);
        printf("hex_element: hourglass energy %.6e J, 1/2 f.u %.6e J\n", ih.hourglass_energy, work);
        check("hourglass energy = 1/2 f.u", ih.hourglass_energy > 0 && fabs(ih.hourglass_energy / work - 1) < 1e-9);
    }
    printf("hex_element: %s\n", failures ? "FAILED" : "all checks hold");
    return failures ? 1 : 0;
}
