/* Shared by the C peers of tests/benchmarks/bench_interpolators.py: timing, the row
 * checksum and the output line. A row is one interpolator iteration (dx, dy), each in
 * {-1, 0, +1}, stored as two int8 in a buffer exactly as camtool's step arrays.
 * Checksum (compared by the Python side with camtool's rows): per case
 * S = sum over rows i of (i + 1) * (3 dx + dy) mod 2^64, folded over the cases as
 * total = total * 1000003 + S (mod 2^64). */
#ifndef CAMTOOL_BENCH_COMMON_H
#define CAMTOOL_BENCH_COMMON_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static uint64_t rows_checksum(const int8_t *rows, int64_t n) {
    uint64_t s = 0;
    for (int64_t i = 0; i < n; i++)
        s += (uint64_t)(i + 1) * (uint64_t)(int64_t)(3 * rows[2 * i] + rows[2 * i + 1]);
    return s;
}

static void *xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    return p;
}

/* "iterations pulses checksum best_seconds" on one line. */
static void report(int64_t iterations, int64_t pulses, uint64_t checksum, double best) {
    printf("%lld %lld %llu %.9f\n", (long long)iterations, (long long)pulses,
           (unsigned long long)checksum, best);
}

/* Checksum and pulse count of the rows of ``count`` cases written one after another
 * (case k has lengths[k] rows), then the report line. */
static void report_rows(const int8_t *rows, const int64_t *lengths, int64_t count,
                        int64_t iterations, double best) {
    uint64_t checksum = 0;
    int64_t pulses = 0, at = 0;
    for (int64_t k = 0; k < count; k++) {
        checksum = checksum * 1000003u + rows_checksum(rows + 2 * at, lengths[k]);
        at += lengths[k];
    }
    for (int64_t i = 0; i < iterations * 2; i++) pulses += rows[i] != 0;
    report(iterations, pulses, checksum, best);
}
#endif
