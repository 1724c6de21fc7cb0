/*
 * The plain-loop limit: the closed-loop servo + LuGre step of lugre.simulate written
 * as one C loop, with nothing else (no events, no effects, no checks).
 *
 * Per control period (one plant step, substeps = 1): reference by linear
 * interpolation on the sample grid, PID update, then one plant step with the exact
 * bristle update and semi-implicit Euler (docs/DESIGN.md, "Plant step", two exp()).
 * Every `dec` steps it records x, v, z, i, F and the motor force, F costing a third
 * exp() as in lugre.
 *
 * Usage: plain_loop <grid.bin> <steps>
 *   grid.bin: int64 m, then m float64 sample times t, then m float64 x_ref (the same
 *   arrays handed to lugre.simulate; t[0] = 0, t[m-1] = steps/rate).
 * Prints one line: "seconds=<s> steps=<n> x=<x> v=<v> z=<z>".
 *
 * Built by benches/compare.py with gcc -O3 (baseline x86-64, like the Rust build: no FMA
 * contraction, so the same arithmetic as lugre) and with -march=native for comparison.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct {
    double fc, fs, sigma2, vs;
} Set;

static const double MASS = 25.0, KF = 25.0;
static const double SIGMA0 = 1e5, SIGMA1 = 31.62;
static const Set POS = {28.7, 60.2, 332.5, 0.01};
static const Set NEG = {28.5, 60.1, 333.0, 0.01};
static const double KP = 5e4, KI = 5e5, KD = 1500.0, RATE = 1e4;

static inline double g_of(const Set *s, double v) {
    double r = v / s->vs;
    return s->fc + (s->fs - s->fc) * exp(-(r * r));
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s grid.bin steps\n", argv[0]);
        return 2;
    }
    FILE *fp = fopen(argv[1], "rb");
    if (!fp) {
        perror(argv[1]);
        return 2;
    }
    int64_t m;
    if (fread(&m, sizeof m, 1, fp) != 1 || m < 2) return 2;
    double *t = malloc(sizeof(double) * m), *xr_in = malloc(sizeof(double) * m);
    if (fread(t, sizeof(double), m, fp) != (size_t)m) return 2;
    if (fread(xr_in, sizeof(double), m, fp) != (size_t)m) return 2;
    fclose(fp);
    long steps = atol(argv[2]);
    long dec = steps / (m - 1);
    double *out = malloc(sizeof(double) * 6 * m);

    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);

    const double h = 1.0 / RATE;
    double x = xr_in[0], v = 0.0, z = 0.0, xi = 0.0, xr_prev = 0.0, ic = 0.0;
    long j = 0, k = 0;
    for (long n = 0; n <= steps; n++) {
        /* controller update at tc = n/rate */
        double tc = n / RATE, xr;
        while (j + 2 < m && t[j + 1] <= tc) j++;
        if (tc >= t[m - 1]) xr = xr_in[m - 1];
        else xr = xr_in[j] + (xr_in[j + 1] - xr_in[j]) * (tc - t[j]) / (t[j + 1] - t[j]);
        double xr_dot = n == 0 ? 0.0 : (xr - xr_prev) * RATE;
        xr_prev = xr;
        double e = xr - x;
        xi += e / RATE;
        ic = (KP * e + KI * xi + KD * (xr_dot - v)) / KF;
        const Set *s = v >= 0.0 ? &POS : &NEG;
        double g = g_of(s, v); /* exp() no. 1 */
        if (n % dec == 0) { /* record sample k */
            double zdot = v - SIGMA0 * fabs(v) * z / g;
            double *o = out + 6 * k++;
            o[0] = x; o[1] = v; o[2] = z; o[3] = ic;
            o[4] = SIGMA0 * z + SIGMA1 * zdot + s->sigma2 * v;
            o[5] = KF * ic;
        }
        if (n == steps) break;
        /* plant step over h */
        double fm = KF * ic;
        double zdot = v - SIGMA0 * fabs(v) * z / g;
        double f = SIGMA0 * z + SIGMA1 * zdot + s->sigma2 * v;
        double acc = (fm - f) / MASS;
        if (v != 0.0) {
            double zss = (v > 0.0 ? 1.0 : -1.0) * g / SIGMA0;
            z = zss + (z - zss) * exp(-(SIGMA0 * fabs(v) * h / g)); /* exp() no. 2 */
        }
        v += acc * h;
        x += v * h;
    }

    clock_gettime(CLOCK_MONOTONIC, &b);
    double sec = (b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec);
    double sum = 0.0; /* keep the outputs alive */
    for (long q = 0; q < 6 * k; q++) sum += out[q];
    printf("seconds=%.9f steps=%ld x=%.17g v=%.17g z=%.17g checksum=%.6g\n", sec, steps, x,
           v, z, sum);
    free(t);
    free(xr_in);
    free(out);
    return 0;
}
