/* Drives material points through the C ABI along the deformation paths of
 * `granbed-cli point` CSV files and checks that the stresses, densities,
 * plastic flags and iteration counts are the CLI's bit for bit.
 *
 * usage: material_paths TYPE FILE.csv [FILE.csv ...]
 *
 * All files are replayed together as one batch (point k follows file k), so
 * the batch layout is exercised too. Each CSV row gives F (f_xx f_yy f_zz
 * f_xy; the other components are zero on these paths); the program updates
 * every point once per row, from the state the previous row left, exactly
 * as the CLI did. Exit status 0 if everything matched. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "granbed.h"

#define MAX_FILES 8
#define MAX_ROWS 100000
#define COLUMNS 24

/* Column indices of the CLI's CSV (see `granbed-cli point --help`). */
enum { C_F_XX = 2, C_F_YY = 3, C_F_ZZ = 4, C_F_XY = 5, C_TAU_XX = 7, C_ETA = 21,
       C_PLASTIC = 22, C_ITERATIONS = 23 };

static double *read_csv(const char *path, size_t *rows) {
    FILE *in = fopen(path, "r");
    if (!in) { perror(path); exit(2); }
    char line[4096];
    if (!fgets(line, sizeof line, in)) { fprintf(stderr, "%s: empty\n", path); exit(2); }
    double *v = malloc(sizeof(double) * COLUMNS * MAX_ROWS);
    size_t n = 0;
    while (n < MAX_ROWS && fgets(line, sizeof line, in)) {
        char *p = line;
        for (int c = 0; c < COLUMNS; c++) {
            char *end;
            v[n * COLUMNS + c] = strtod(p, &end); /* correctly rounded: exact round trip */
            if (end == p) { fprintf(stderr, "%s: bad row %zu\n", path, n); exit(2); }
            p = end + (*end == ',');
        }
        n++;
    }
    fclose(in);
    *rows = n;
    return v;
}

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

int main(int argc, char **argv) {
    if (argc < 3 || argc - 2 > MAX_FILES) {
        fprintf(stderr, "usage: %s TYPE FILE.csv [FILE.csv ...] (at most %d files)\n", argv[0], MAX_FILES);
        return 2;
    }
    GranbedMaterialParams params;
    int32_t s = granbed_material_preset(argv[1], &params);
    if (s != GRANBED_OK) { fprintf(stderr, "preset %s: %s\n", argv[1], granbed_status_message(s)); return 2; }

    size_t npts = (size_t)(argc - 2), rows = 0;
    double *csv[MAX_FILES];
    for (size_t k = 0; k < npts; k++) {
        size_t r;
        csv[k] = read_csv(argv[2 + k], &r);
        if (k > 0 && r != rows) { fprintf(stderr, "files differ in row count\n"); return 2; }
        rows = r;
    }

    double cp_inv[MAX_FILES * 6], f[MAX_FILES * 9], tau[MAX_FILES * 6];
    GranbedPointInfo info[MAX_FILES];
    int32_t status[MAX_FILES];
    granbed_state_init(npts, cp_inv);
    size_t mismatches = 0, plastic_rows = 0;
    for (size_t r = 0; r < rows; r++) {
        for (size_t k = 0; k < npts; k++) {
            const double *row = csv[k] + r * COLUMNS;
            double *fk = f + 9 * k; /* row-major F */
            memset(fk, 0, 9 * sizeof(double));
            fk[0] = row[C_F_XX]; fk[4] = row[C_F_YY]; fk[8] = row[C_F_ZZ]; fk[1] = row[C_F_XY];
        }
        s = granbed_update_points(&params, 1, npts, f, cp_inv, GRANBED_STRESS_KIRCHHOFF, tau, info, status);
        if (s != GRANBED_OK) { fprintf(stderr, "row %zu: %s\n", r, granbed_status_message(s)); return 1; }
        for (size_t k = 0; k < npts; k++) {
            const double *row = csv[k] + r * COLUMNS;
            int ok = 1;
            for (int c = 0; c < 6; c++) ok &= same_bits(tau[6 * k + c], row[C_TAU_XX + c]);
            ok &= same_bits(info[k].eta, row[C_ETA]);
            ok &= info[k].plastic == (int32_t)row[C_PLASTIC];
            ok &= info[k].iterations == (int32_t)row[C_ITERATIONS];
            plastic_rows += (size_t)info[k].plastic;
            if (!ok && mismatches++ < 5)
                fprintf(stderr, "%s row %zu: tau_zz %.17g vs CLI %.17g\n", argv[2 + k], r,
                        tau[6 * k + 2], row[C_TAU_XX + 2]);
        }
    }
    printf("material_paths: %zu points x %zu rows (%zu plastic updates): %zu mismatches\n",
           npts, rows, plastic_rows, mismatches);
    if (plastic_rows == 0) { fprintf(stderr, "no plastic update: the paths test nothing\n"); return 1; }
    return mismatches == 0 ? 0 : 1;
}
