/* A C program that uses a compiled Frac model without Frac or LLVM (examples/aot/README.md).
 *
 *   frac compile model.frac -o model.o --header model.h
 *   cc -I. main.c model.o -lstdc++ -lm -o main
 * or, with a shared library:
 *   frac compile model.frac -o model.so --header model.h
 *   cc -I. main.c -L. -l:model.so -Wl,-rpath,'$ORIGIN' -o main
 *
 * It prints one line per evaluation, numbers in C's exact hexadecimal form and, after '#', in decimal:
 *   point|points SHAPE X Y [Z] = VALUE
 *   box|boxes    SHAPE XLO XHI YLO YHI [ZLO ZHI] = LO HI
 * (tests/aot checks every line against the Frac JIT, bit for bit). */
#include "model.h"

#include <stdio.h>

static void print_point(const char* kind, const char* shape, const double* p, int d, double value) {
    printf("%s %s", kind, shape);
    for (int k = 0; k < d; ++k) printf(" %a", p[k]);
    printf(" = %a  # %.17g\n", value, value);
}

static void print_box(const char* kind, const char* shape, const frac_interval* box, int d, frac_interval r) {
    printf("%s %s", kind, shape);
    for (int k = 0; k < d; ++k) printf(" %a %a", box[k].lo, box[k].hi);
    printf(" = %a %a  # [%.17g, %.17g]%s\n", r.lo, r.hi, r.lo, r.hi,
           r.lo > 0   ? " outside"
           : r.hi < 0 ? " inside"
                      : "");
}

static void describe(const char* shape, int d, const frac_interval* box) {
    printf("# %s: %d coordinates, default box", shape, d);
    for (int k = 0; k < d; ++k) printf("%s[%.17g, %.17g]", k ? " x " : " ", box[k].lo, box[k].hi);
    printf("\n");
}

/* The default box cut into n^d cells (d <= 3), for the batch calls. */
static size_t grid(const frac_interval* box, int d, int n, frac_interval* cells) {
    size_t count = 0;
    int idx[3] = {0, 0, 0};
    for (;;) {
        for (int k = 0; k < d; ++k) {
            const double w = (box[k].hi - box[k].lo) / n;
            cells[count * d + k].lo = box[k].lo + w * idx[k];
            cells[count * d + k].hi = box[k].lo + w * (idx[k] + 1);
        }
        ++count;
        int k = 0;
        while (k < d && ++idx[k] == n) idx[k++] = 0;
        if (k == d) return count;
    }
}

int main(void) {
    /* The carpet: single points and boxes. */
    const int dc = frac_carpet_dimension();
    const frac_interval* carpet_box = frac_carpet_default_box();
    describe("carpet", dc, carpet_box);
    const double carpet_points[][2] = {{0.5, 0.5}, {0.1, 0.2}, {1.0 / 9, 0.7}, {0.0, 0.0}, {0.95, 1.0 / 3}};
    for (size_t i = 0; i < sizeof carpet_points / sizeof carpet_points[0]; ++i)
        print_point("point", "carpet", carpet_points[i], dc, frac_carpet_eval_point(carpet_points[i]));
    const frac_interval carpet_boxes[][2] = {{{0.4, 0.6}, {0.4, 0.6}},
                                             {{0.0, 1.0}, {0.0, 1.0}},
                                             {{0.3, 0.34}, {0.1, 0.2}},
                                             {{0.5, 0.5}, {0.25, 0.25}}};
    for (size_t i = 0; i < sizeof carpet_boxes / sizeof carpet_boxes[0]; ++i)
        print_box("box", "carpet", carpet_boxes[i], dc, frac_carpet_eval_box(carpet_boxes[i]));

    /* Batches: the default box cut into 4 x 4 cells, and their lower corners as points. */
    frac_interval cells[64 * 3];
    frac_interval enclosures[64];
    double corners[64 * 3];
    double values[64];
    size_t n = grid(carpet_box, dc, 4, cells);
    frac_carpet_eval_boxes(cells, n, enclosures);
    for (size_t i = 0; i < n; ++i) print_box("boxes", "carpet", cells + i * dc, dc, enclosures[i]);
    for (size_t i = 0; i < n * dc; ++i) corners[i] = cells[i].lo;
    frac_carpet_eval_points(corners, n, values);
    for (size_t i = 0; i < n; ++i) print_point("points", "carpet", corners + i * dc, dc, values[i]);

    /* The wavy ball: a point, a box and the default box cut into 4 x 4 x 4 cells. */
    const int dw = frac_wavy_ball_dimension();
    const frac_interval* ball_box = frac_wavy_ball_default_box();
    describe("wavy_ball", dw, ball_box);
    const double centre[3] = {0.0, 0.0, 0.0}, near_surface[3] = {0.6, 0.7, 0.3};
    print_point("point", "wavy_ball", centre, dw, frac_wavy_ball_eval_point(centre));
    print_point("point", "wavy_ball", near_surface, dw, frac_wavy_ball_eval_point(near_surface));
    const frac_interval corner_box[3] = {{1.4, 1.5}, {1.4, 1.5}, {1.4, 1.5}};
    print_box("box", "wavy_ball", corner_box, dw, frac_wavy_ball_eval_box(corner_box));
    n = grid(ball_box, dw, 4, cells);
    frac_wavy_ball_eval_boxes(cells, n, enclosures);
    size_t inside = 0, outside = 0;
    for (size_t i = 0; i < n; ++i) {
        print_box("boxes", "wavy_ball", cells + i * dw, dw, enclosures[i]);
        inside += enclosures[i].hi < 0;
        outside += enclosures[i].lo > 0;
    }
    printf("# wavy_ball on %zu cells: %zu inside, %zu outside, %zu on the boundary\n", n, inside, outside,
           n - inside - outside);
    return 0;
}
