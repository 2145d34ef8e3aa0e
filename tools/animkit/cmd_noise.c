/* animkit noise: evaluate a noise basis or a fractal sum of it at one point. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char* const usage =
    "usage: animkit noise perlin|simplex|value|worley X[,Y[,Z[,W]]] [--seed K] [--gradient]\n"
    "                     [--octaves N --lacunarity L --gain G --type fbm|turbulence|ridged]\n"
    "Print the noise at the point with 9 significant digits on one line; with --gradient the\n"
    "value followed by its derivative d/dx [d/dy ...]. Coordinates are lattice units.\n"
    "  perlin   improved Perlin noise, 1 to 4 coordinates (seed 0 = Perlin's reference)\n"
    "  simplex  simplex noise, 1 to 3 coordinates (1: the 2D noise at y = 0)\n"
    "  value    value noise, 1 to 4 coordinates\n"
    "  worley   cellular noise F1 (distance to the nearest feature point), 1 to 3 coordinates\n"
    "  --seed       permutation seed, 0 to 18446744073709551615 (default 0)\n"
    "  --octaves    1 to 16 (default 6 when any fractal option is given)\n"
    "  --lacunarity frequency ratio, in (0, 16] (default 2)\n"
    "  --gain       amplitude ratio, in (0, 2] (default 0.5)\n"
    "  --type       fractal sum (default fbm); without any fractal option: the plain basis\n";

static bool parse_seed(const char* s, uint64_t* out) {
    if (!s || !*s || *s == '-' || *s == '+') return false;
    char* end = NULL;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end != '\0') return false;
    *out = (uint64_t)v;
    return true;
}

/* "X[,Y[,Z[,W]]]" -> 1..4 finite floats */
static int parse_point(const char* s, float* p) {
    char buf[256];
    if (!s || strlen(s) >= sizeof buf) return 0;
    strcpy(buf, s);
    int n = 0;
    char* save = NULL;
    for (char* tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (n == 4 || !cli_parse_float(tok, &p[n])) return 0;
        ++n;
    }
    return n;
}

int cmd_noise(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--seed", NULL, true},       {"--octaves", NULL, true}, {"--lacunarity", NULL, true},
        {"--gain", NULL, true},       {"--type", NULL, true},    {"--gradient", NULL, false},
    };
    cli_args a;
    int rc = cli_parse("noise", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 2) return cli_usage("noise", "expected a basis (perlin|simplex|value|worley) and a point X[,Y[,Z[,W]]]");
    static const struct {
        const char* name;
        ak_noise_basis basis;
    } bases[] = {{"perlin", AK_NOISE_BASIS_PERLIN},
                 {"simplex", AK_NOISE_BASIS_SIMPLEX},
                 {"value", AK_NOISE_BASIS_VALUE},
                 {"worley", AK_NOISE_BASIS_WORLEY}};
    int bi = -1;
    for (int i = 0; i < 4; ++i)
        if (strcmp(a.pos[0], bases[i].name) == 0) bi = i;
    if (bi < 0) return cli_usage("noise", "unknown basis '%s': allowed perlin, simplex, value, worley", a.pos[0]);
    const ak_noise_basis basis = bases[bi].basis;
    float p[4] = {0, 0, 0, 0};
    const int dims = parse_point(a.pos[1], p);
    if (dims == 0)
        return cli_usage("noise", "point '%s' is not 1 to 4 comma-separated numbers X[,Y[,Z[,W]]]", a.pos[1]);
    if (!ak_noise_basis_supports(basis, (uint32_t)dims))
        return cli_usage("noise", "%s takes 1 to %d coordinates, got %d", bases[bi].name,
                         basis == AK_NOISE_BASIS_SIMPLEX || basis == AK_NOISE_BASIS_WORLEY ? 3 : 4, dims);
    for (int k = 0; k < dims; ++k)
        if (!(fabsf(p[k]) < 16777216.0f))
            return cli_usage("noise", "coordinate %g is outside the allowed range (-16777216, 16777216)", (double)p[k]);
    uint64_t seed = 0;
    if (CLI_GET(&a, "--seed") && !parse_seed(CLI_GET(&a, "--seed"), &seed))
        return cli_usage("noise", "--seed '%s': allowed range 0 to 18446744073709551615", CLI_GET(&a, "--seed"));

    ak_fractal_desc fd = {.basis = basis, .octaves = 1};
    const char* s_oct = CLI_GET(&a, "--octaves");
    const char* s_lac = CLI_GET(&a, "--lacunarity");
    const char* s_gain = CLI_GET(&a, "--gain");
    const char* s_type = CLI_GET(&a, "--type");
    if (s_oct || s_lac || s_gain || s_type) {
        fd.octaves = 6;
        long oct;
        if (s_oct && !cli_parse_int(s_oct, 1, 16, &oct))
            return cli_usage("noise", "--octaves '%s': allowed range 1 to 16", s_oct);
        if (s_oct) fd.octaves = (uint32_t)oct;
        if (s_lac && (!cli_parse_float(s_lac, &fd.lacunarity) || !(fd.lacunarity > 0.0f && fd.lacunarity <= 16.0f)))
            return cli_usage("noise", "--lacunarity '%s': allowed range (0, 16]", s_lac);
        if (s_gain && (!cli_parse_float(s_gain, &fd.gain) || !(fd.gain > 0.0f && fd.gain <= 2.0f)))
            return cli_usage("noise", "--gain '%s': allowed range (0, 2]", s_gain);
        if (s_type) {
            if (strcmp(s_type, "fbm") == 0) fd.type = AK_FRACTAL_FBM;
            else if (strcmp(s_type, "turbulence") == 0) fd.type = AK_FRACTAL_TURBULENCE;
            else if (strcmp(s_type, "ridged") == 0) fd.type = AK_FRACTAL_RIDGED;
            else return cli_usage("noise", "--type '%s': allowed fbm, turbulence, ridged", s_type);
        }
    }
    const ak_noise n = ak_noise_make(seed);
    float g[4] = {0, 0, 0, 0};
    const bool want_grad = CLI_GET(&a, "--gradient") != NULL;
    const float v = ak_fractal_eval(&n, &fd, (uint32_t)dims, p, want_grad ? g : NULL);
    printf("%.9g", (double)v);
    if (want_grad)
        for (int k = 0; k < dims; ++k) printf(" %.9g", (double)g[k]);
    printf("\n");
    return CLI_OK;
}
