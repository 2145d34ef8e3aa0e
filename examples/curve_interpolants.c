/* curve_interpolants: the same five keys under every scalar interpolation mode, printed as a
 * table (time, then one column per mode) to stdout and to curve_interpolants.csv, plus an
 * eased time ramp and a path walked at constant speed through its arc-length table. */
#include <animkit/curve.h>

#include <stdio.h>

int main(void) {
    const float times[5] = {0.0f, 0.6f, 1.0f, 2.2f, 3.0f};
    const float values[5] = {0.0f, 1.0f, 0.2f, 0.8f, 0.0f};
    /* HERMITE / CUBICSPLINE: (in-tangent, value, out-tangent) per key. */
    float hermite[15];
    /* BEZIER: (value, out-control, in-control) per key. */
    float bezier[15];
    for (int k = 0; k < 5; ++k) {
        hermite[k * 3 + 0] = 0.0f;
        hermite[k * 3 + 1] = values[k];
        hermite[k * 3 + 2] = k % 2 ? -1.0f : 1.0f;
        bezier[k * 3 + 0] = values[k];
        bezier[k * 3 + 1] = values[k] + 0.3f;
        bezier[k * 3 + 2] = values[k] - 0.3f;
    }
    const ak_interp modes[] = {AK_INTERP_STEP,     AK_INTERP_LINEAR, AK_INTERP_HERMITE,
                               AK_INTERP_CARDINAL, AK_INTERP_BEZIER, AK_INTERP_NATURAL,
                               AK_INTERP_LAGRANGE};
    enum { MODES = sizeof modes / sizeof modes[0] };
    ak_track* tracks[MODES] = {0};
    for (int m = 0; m < MODES; ++m) {
        const float* v = modes[m] == AK_INTERP_HERMITE ? hermite
                         : modes[m] == AK_INTERP_BEZIER ? bezier
                                                        : values;
        ak_raw_track raw = {.interp = modes[m], .tension = 0.5f, .key_count = 5, .times = times, .values = v};
        ak_diag diag;
        ak_result r = ak_track_build(&raw, NULL, &tracks[m], &diag);
        if (r != AK_OK) {
            fprintf(stderr, "build %s: %s (%s)\n", ak_interp_name(modes[m]), ak_result_string(r), diag.message);
            return 1;
        }
    }
    FILE* csv = fopen("curve_interpolants.csv", "w");
    printf("%6s", "t");
    for (int m = 0; m < MODES; ++m) printf(" %9s", ak_interp_name(modes[m]));
    printf("\n");
    if (csv) {
        fprintf(csv, "t");
        for (int m = 0; m < MODES; ++m) fprintf(csv, ",%s", ak_interp_name(modes[m]));
        fprintf(csv, "\n");
    }
    for (int i = 0; i <= 60; ++i) {
        float t = 3.0f * (float)i / 60.0f;
        if (i % 5 == 0) printf("%6.2f", (double)t);
        if (csv) fprintf(csv, "%g", (double)t);
        for (int m = 0; m < MODES; ++m) {
            float v;
            ak_track_sample(tracks[m], t, (ak_f32_span){&v, 1});
            if (i % 5 == 0) printf(" %9.4f", (double)v);
            if (csv) fprintf(csv, ",%g", (double)v);
        }
        if (i % 5 == 0) printf("\n");
        if (csv) fprintf(csv, "\n");
    }
    if (csv) fclose(csv);

    /* Velocity and acceleration of the natural spline at a key: continuous (C2). */
    float vel, acc;
    ak_track_derivative(tracks[5], 1.0f, 1, (ak_f32_span){&vel, 1});
    ak_track_derivative(tracks[5], 1.0f, 2, (ak_f32_span){&acc, 1});
    printf("natural spline at t=1: velocity %.4f, acceleration %.4f\n", (double)vel, (double)acc);

    /* Slow in, slow out over a 2 s move. */
    printf("ease sine in-out over 2 s:");
    for (int i = 0; i <= 4; ++i) printf(" %.3f", (double)ak_ease_time(AK_EASE_SINE_IN_OUT, 0.5f * (float)i, 2.0f));
    printf("\n");

    /* Constant speed along a Catmull-Rom path. */
    float pts[15] = {0, 0, 0, 1, 0, 0, 1.2f, 0, 3, 4, 0, 3.5f, 5, 0, 0};
    ak_raw_track path_raw = {.component_count = 3, .interp = AK_INTERP_CARDINAL, .key_count = 5, .times = times,
                             .values = pts};
    ak_track* path = NULL;
    ak_arc_table* arc = NULL;
    if (ak_track_build(&path_raw, NULL, &path, NULL) != AK_OK ||
        ak_arc_table_create(&(ak_arc_table_desc){.path = path}, NULL, &arc) != AK_OK)
        return 1;
    float len = ak_arc_table_length(arc);
    printf("path length %.4f; equal distance steps:\n", (double)len);
    for (int i = 0; i <= 8; ++i) {
        float s = len * (float)i / 8.0f, p[3];
        float t = ak_arc_table_time_at(arc, s);
        ak_track_sample(path, t, (ak_f32_span){p, 3});
        printf("  s=%6.3f  t=%6.3f  p=(%.3f, %.3f, %.3f)\n", (double)s, (double)t, (double)p[0], (double)p[1],
               (double)p[2]);
    }
    ak_arc_table_destroy(arc);
    ak_track_destroy(path);
    for (int m = 0; m < MODES; ++m) ak_track_destroy(tracks[m]);
    return 0;
}
