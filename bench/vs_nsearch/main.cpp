// animkit's neighbour grid beside CompactNSearch (the neighbour search of SPlisHSPlasH) on the
// same jittered particle lattice (spacing h/2, jitter +-10% of it, radius h), same process,
// interleaved rounds (the order of the three contenders rotates each round):
//   ak pairs : ak_grid_build + ak_grid_pairs_run (every pair i < j once)
//   ak lists : ak_grid_build + ak_grid_neighbors_run (CSR lists, both directions)
//   CNS      : NeighborhoodSearch::find_neighbors on a persistent search (lists, both directions)
// Checks that all three find the same set (order-independent hashes), prints medians of wall
// and process CPU time, per-round CPU ratios CNS / animkit, and CPU ns per pair.
// Usage: bench/vs_nsearch/run.sh [BUILD_DIR] [SIDE] [ROUNDS] [z]   (AK_SCALAR=1: animkit's
// scalar loops instead of its AVX-512 kernels)
#include <CompactNSearch>
#include <omp.h>
#include <time.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>
extern "C" {
size_t ak_pairs_step(const float* p, size_t n, float r, unsigned threads, double* tb, double* tr);
size_t ak_csr_step(const float* p, size_t n, float r, unsigned threads, double* tb, double* tr);
unsigned long long ak_pairs_hash(size_t count);
unsigned long long ak_csr_hash(size_t n);
void ak_free_all(void);
}
static double pcpu() { timespec t; clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
static double wall() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
static double med(std::vector<double> v, double* lo = nullptr, double* hi = nullptr) {
    std::sort(v.begin(), v.end());
    if (lo) *lo = v.front();
    if (hi) *hi = v.back();
    size_t n = v.size();
    return n & 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
static unsigned long long mix(unsigned long long i, unsigned long long j) {
    unsigned long long x = (i << 32 | j) * 0x9E3779B97F4A7C15ull;
    return x ^ (x >> 29);
}
int main(int argc, char** argv) {
    int side = argc > 1 ? atoi(argv[1]) : 38;
    int R = argc > 2 ? atoi(argv[2]) : 5;
    bool zs = argc > 3 && argv[3][0] == 'z';
    const float h = 0.1f, s = h / 2;
    size_t n = (size_t)side * side * side;
    std::vector<float> p(3 * n);
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> U(-0.1f * s, 0.1f * s);
    size_t q = 0;
    for (int k = 0; k < side; ++k)
        for (int j = 0; j < side; ++j)
            for (int i = 0; i < side; ++i) p[q++] = i * s + U(rng), p[q++] = j * s + U(rng), p[q++] = k * s + U(rng);
    if (zs) {
        CompactNSearch::NeighborhoodSearch tmp(h);
        unsigned tid = tmp.add_point_set(p.data(), n, true, true);
        tmp.z_sort();
        tmp.point_set(tid).sort_field(reinterpret_cast<std::array<float, 3>*>(p.data()));
    }
    const char* sc = getenv("AK_SCALAR");
    printf("%zu points (%d^3 lattice, spacing h/2, jitter +-10%%), radius h, %s order, animkit %s\n", n, side,
           zs ? "CNS z-curve" : "lattice", sc && sc[0] == '1' ? "scalar loops" : "default kernels");
    CompactNSearch::NeighborhoodSearch ns(h);
    unsigned id = ns.add_point_set(p.data(), n, true, true);
    ns.find_neighbors();
    double tb, tr;
    size_t pc = ak_pairs_step(p.data(), n, h, 1, &tb, &tr);
    unsigned long long ph = ak_pairs_hash(pc);
    size_t lc = ak_csr_step(p.data(), n, h, 1, &tb, &tr);
    unsigned long long lh = ak_csr_hash(n);
    const auto& ps = ns.point_set(id);
    size_t cs = 0;
    unsigned long long cph = 0, clh = 0;
    for (unsigned i = 0; i < ps.n_points(); ++i)
        for (unsigned k = 0; k < ps.n_neighbors(id, i); ++k) {
            unsigned j = ps.neighbor(id, i, k);
            ++cs, clh += mix(i, j);
            if (i < j) cph += mix(i, j);
        }
    bool same = pc * 2 == cs && lc == cs && ph == cph && lh == clh;
    printf("pairs %zu, list entries: animkit %zu, CNS %zu; sets %s\n", pc, lc, cs, same ? "EQUAL" : "DIFFERENT");
    if (!same) return 1;
    for (int th = 1; th <= 2; ++th) {
        omp_set_num_threads(th);
        std::vector<double> w[3], c[3], rp, rl;
        for (int r = 0; r < R; ++r) {
            double wt[3], ct[3];
            for (int k = 0; k < 3; ++k) {
                int who = (k + r) % 3;
                double c0 = pcpu(), w0 = wall();
                if (who == 0) ak_pairs_step(p.data(), n, h, th, &tb, &tr);
                else if (who == 1) ak_csr_step(p.data(), n, h, th, &tb, &tr);
                else ns.find_neighbors();
                wt[who] = wall() - w0, ct[who] = pcpu() - c0;
            }
            for (int k = 0; k < 3; ++k) w[k].push_back(wt[k]), c[k].push_back(ct[k]);
            rp.push_back(ct[2] / ct[0]), rl.push_back(ct[2] / ct[1]);
        }
        const char* name[3] = {"animkit build+pairs", "animkit build+lists", "CNS find_neighbors "};
        for (int k = 0; k < 3; ++k) {
            double lo, hi, mc = med(c[k], &lo, &hi);
            printf("threads %d  %s  CPU %9.2f ms [%.2f-%.2f]  wall %9.2f ms  CPU ns/pair %6.2f\n", th, name[k],
                   1e3 * mc, 1e3 * lo, 1e3 * hi, 1e3 * med(w[k]), 1e9 * mc / (double)pc);
        }
        double lo, hi, m = med(rp, &lo, &hi);
        printf("threads %d  per-round CPU ratio CNS / animkit pairs: median %.2f [%.2f-%.2f]", th, m, lo, hi);
        m = med(rl, &lo, &hi);
        printf("; CNS / animkit lists: median %.2f [%.2f-%.2f]\n", m, lo, hi);
        printf("threads %d  wall ratio (medians) CNS / pairs %.2f, CNS / lists %.2f\n", th, med(w[2]) / med(w[0]),
               med(w[2]) / med(w[1]));
    }
    ak_free_all();
    return 0;
}
