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
    expect("vumat nstatev 5", granbed_vumat(1, 5, 8, NULL, NULL, NULL, NULL, NULL, NULL), GRANBED_ERR_INVALID_ARGUMENT);
    if (strcmp(granbed_status_message(12345), "unknown status code") != 0) {
        fprintf(stderr, "FAIL: unknown code message\n");
        failures++;
    }
    printf("errors: %s (library %s)\n", failures ? "FAILED" : "all cases gave the documented status",
           granbed_version());
    return failures ? 1 : 0;
}
