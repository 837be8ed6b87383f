/* Linear DDA of the GMM PIC controller, UNAM-GMM §4.2, annex A.3 (reference/UNAM-GMM.md
 * §4.2, "Pseudo-code [derived from A.3]"), as a C peer of camtool's dda_line:
 *
 *   PX=|dx|; PY=|dy|; HIPO=sqrt(PX²+PY²); QX=QY=0; CX=CY=0
 *   loop: QX+=PX; if CX<PX and QX>HIPO: QX-=HIPO; CX+=1; step X
 *         QY+=PY; if CY<PY and QY>HIPO: QY-=HIPO; CY+=1; step Y
 *         (one row per iteration)      if CX>=PX and CY>=PY: stop
 *
 * HIPO and the accumulators are doubles (the thesis does not say how the PIC holds
 * them). Usage: dda CASES REPEATS, CASES a text file of "dx dy" lines. Every repeat runs
 * all cases into one row buffer; prints iterations, pulses, checksum, best time (s). */
#include <math.h>
#include "common.h"

static int64_t dda(int64_t dx, int64_t dy, int8_t *out) {
    int64_t px = dx < 0 ? -dx : dx, py = dy < 0 ? -dy : dy;
    int8_t sx = dx < 0 ? -1 : 1, sy = dy < 0 ? -1 : 1;
    double hipo = sqrt((double)px * (double)px + (double)py * (double)py);
    double qx = 0.0, qy = 0.0, fpx = (double)px, fpy = (double)py;
    int64_t cx = 0, cy = 0, n = 0;
    while (cx < px || cy < py) {
        int8_t ox = 0, oy = 0;
        qx += fpx;
        if (cx < px && qx > hipo) { qx -= hipo; cx++; ox = sx; }
        qy += fpy;
        if (cy < py && qy > hipo) { qy -= hipo; cy++; oy = sy; }
        out[2 * n] = ox;
        out[2 * n + 1] = oy;
        n++;
    }
    return n;
}

int main(int argc, char **argv) {
    if (argc != 3) { fprintf(stderr, "usage: dda CASES REPEATS\n"); return 2; }
    FILE *f = fopen(argv[1], "r");
    if (!f) { perror(argv[1]); return 2; }
    int repeats = atoi(argv[2]);
    int64_t cap = 1024, count = 0, total = 0;
    int64_t *cases = xmalloc(sizeof(int64_t) * 2 * cap);
    long long a, b;
    while (fscanf(f, "%lld %lld", &a, &b) == 2) {
        if (count == cap) {
            cap *= 2;
            int64_t *grown = realloc(cases, sizeof(int64_t) * 2 * cap);
            if (!grown) { fprintf(stderr, "out of memory\n"); return 2; }
            cases = grown;
        }
        cases[2 * count] = a;
        cases[2 * count + 1] = b;
        /* rows: floor(HIPO) + 1 at most; + 2 for safety */
        total += (int64_t)sqrt((double)a * a + (double)b * b) + 2;
        count++;
    }
    fclose(f);
    int8_t *rows = xmalloc((size_t)total * 2);
    for (int64_t i = 0; i < total * 2; i++) rows[i] = 0; /* touch the pages before timing */
    double best = 1e300;
    int64_t iterations = 0;
    int64_t *lengths = xmalloc(sizeof(int64_t) * (count ? count : 1));
    for (int r = 0; r < repeats; r++) {
        double t0 = now_s();
        int64_t at = 0;
        for (int64_t c = 0; c < count; c++) {
            lengths[c] = dda(cases[2 * c], cases[2 * c + 1], rows + 2 * at);
            at += lengths[c];
        }
        double t = now_s() - t0;
        if (t < best) best = t;
        iterations = at;
    }
    report_rows(rows, lengths, count, iterations, best);
    return 0;
}
