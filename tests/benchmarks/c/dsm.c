/* Direct Search Method of the GMM PIC controller, UNAM-GMM §4.5, annex A.6
 * (reference/UNAM-GMM.md §4.5, "Code (verbatim, A.6)"), as a C peer of camtool's dsm_arc.
 *
 * The inner loop is the annex's: D1 = |D + DeltaX|, D2 = |D + DeltaY|,
 * D3 = |D + DeltaX + DeltaY|; if D1 > D2 the diagonal wins only when D2 > D3 (else Y),
 * otherwise the diagonal wins only when D1 > D3 (else X); DeltaX/DeltaY += 2 after a step
 * on their axis; CUAD1/CUAD2 initialisation by quadrant and sense. Around it, the same
 * quadrant plan, end rule and closing steps as camtool (camtool/verify/interpolators.py
 * module docstring: R from the start, D0 = 0, a quadrant that is not the last ends on the
 * axis). Usage: dsm CASES REPEATS, CASES a file of "x0 y0 x1 y1 cx cy cw" lines (steps;
 * cw 1 for G02). Prints iterations, pulses, checksum, best time (s). */
#include "common.h"

typedef struct { int64_t u, v; } quadrant;

static int64_t sgn(int64_t v) { return (v > 0) - (v < 0); }

static quadrant depart(int64_t u, int64_t v, int cw) {
    quadrant q;
    if (u && v) { q.u = sgn(u); q.v = sgn(v); return q; }
    if (u == 0) {
        int64_t s = v > 0 ? 1 : -1;
        q.u = cw ? s : -s; q.v = s; return q;
    }
    int64_t s = u > 0 ? 1 : -1;
    q.u = s; q.v = cw ? -s : s; return q;
}

static quadrant next_quad(quadrant q, int cw) {
    quadrant n;
    if (cw) { n.u = q.v; n.v = -q.u; } else { n.u = -q.v; n.v = q.u; }
    return n;
}

static int64_t dsm_arc(int64_t x0, int64_t y0, int64_t x1, int64_t y1, int64_t cx, int64_t cy,
                       int cw, int8_t *out) {
    int64_t u0 = x0 - cx, v0 = y0 - cy, u1 = x1 - cx, v1 = y1 - cy;
    quadrant plan[8];
    int np = 1;
    plan[0] = depart(u0, v0, cw);
    quadrant end = depart(u1, v1, !cw);
    int64_t cross = u0 * v1 - v0 * u1;
    int ahead = cw ? cross < 0 : cross > 0;
    while (np < 8 && (plan[np - 1].u != end.u || plan[np - 1].v != end.v || (np == 1 && !ahead))) {
        plan[np] = next_quad(plan[np - 1], cw);
        np++;
    }
    int64_t u = u0, v = v0, d = 0, n = 0;
    int64_t ax1 = u1 < 0 ? -u1 : u1, ay1 = v1 < 0 ? -v1 : v1;
    for (int i = 0; i < np; i++) {
        quadrant q = plan[i];
        int grows_x = ((q.u * q.v > 0) == (cw != 0));
        int64_t gx = grows_x ? 1 : -1, gy = -gx;
        int64_t x = u < 0 ? -u : u, y = v < 0 ? -v : v;
        int64_t sx, sy; /* stop magnitudes; -1 never matches */
        if (i != np - 1) {
            sx = gx > 0 ? -1 : 0; sy = gx > 0 ? 0 : -1;
        } else if (ax1 <= ay1) {
            int reached = gx > 0 ? ax1 <= x : ax1 >= x;
            sx = reached ? x : ax1; sy = gx > 0 ? 0 : -1;
        } else {
            int reached = gx > 0 ? ay1 >= y : ay1 <= y;
            sx = gx > 0 ? -1 : 0; sy = reached ? y : ay1;
        }
        int8_t ux = (int8_t)(q.u * gx), uy = (int8_t)(-q.v * gx);
        int64_t dx = 2 * x * gx + 1, dy = 2 * y * gy + 1; /* DSMCIRCULARCUAD1 / CUAD2 */
        while (x != sx && y != sy) {
            int64_t d1 = d + dx, d2 = d + dy, d3 = d1 + dy;
            int64_t a1 = d1 >= 0 ? d1 : -d1, a2 = d2 >= 0 ? d2 : -d2, a3 = d3 >= 0 ? d3 : -d3;
            if (a1 > a2 ? a2 > a3 : a1 > a3) { /* both axes */
                d = d3; dx += 2; dy += 2; x += gx; y += gy;
                out[2 * n] = ux; out[2 * n + 1] = uy;
            } else if (a1 > a2) { /* Y */
                d = d2; dy += 2; y += gy;
                out[2 * n] = 0; out[2 * n + 1] = uy;
            } else { /* X */
                d = d1; dx += 2; x += gx;
                out[2 * n] = ux; out[2 * n + 1] = 0;
            }
            n++;
        }
        u = q.u * x; v = q.v * y;
    }
    /* closing steps, corte-recto style: diagonal, then one axis */
    int64_t du = u1 - u, dv = v1 - v, adu = du < 0 ? -du : du, adv = dv < 0 ? -dv : dv;
    int64_t m = adu > adv ? adu : adv;
    for (int64_t k = 0; k < m; k++) {
        out[2 * n] = (int8_t)(k < adu ? sgn(du) : 0);
        out[2 * n + 1] = (int8_t)(k < adv ? sgn(dv) : 0);
        n++;
    }
    return n;
}

int main(int argc, char **argv) {
    if (argc != 3) { fprintf(stderr, "usage: dsm CASES REPEATS\n"); return 2; }
    FILE *f = fopen(argv[1], "r");
    if (!f) { perror(argv[1]); return 2; }
    int repeats = atoi(argv[2]);
    int64_t cap = 64, count = 0, total = 0;
    int64_t *cases = xmalloc(sizeof(int64_t) * 7 * cap);
    long long c[7];
    while (fscanf(f, "%lld %lld %lld %lld %lld %lld %lld", &c[0], &c[1], &c[2], &c[3], &c[4],
                  &c[5], &c[6]) == 7) {
        if (count == cap) {
            cap *= 2;
            int64_t *grown = realloc(cases, sizeof(int64_t) * 7 * cap);
            if (!grown) { fprintf(stderr, "out of memory\n"); return 2; }
            cases = grown;
        }
        for (int k = 0; k < 7; k++) cases[7 * count + k] = c[k];
        /* rows: at most 2 per step of each magnitude per quadrant (5 quadrants) + closing */
        int64_t r = (c[0] - c[4] < 0 ? c[4] - c[0] : c[0] - c[4]) +
                    (c[1] - c[5] < 0 ? c[5] - c[1] : c[1] - c[5]);
        total += 10 * (r + 2) + 64;
        count++;
    }
    fclose(f);
    int8_t *rows = xmalloc((size_t)total * 2);
    for (int64_t i = 0; i < total * 2; i++) rows[i] = 0; /* touch the pages before timing */
    int64_t *lengths = xmalloc(sizeof(int64_t) * (count ? count : 1));
    double best = 1e300;
    int64_t iterations = 0;
    for (int r = 0; r < repeats; r++) {
        double t0 = now_s();
        int64_t at = 0;
        for (int64_t k = 0; k < count; k++) {
            const int64_t *a = cases + 7 * k;
            lengths[k] = dsm_arc(a[0], a[1], a[2], a[3], a[4], a[5], (int)a[6], rows + 2 * at);
            at += lengths[k];
        }
        double t = now_s() - t0;
        if (t < best) best = t;
        iterations = at;
    }
    report_rows(rows, lengths, count, iterations, best);
    return 0;
}
