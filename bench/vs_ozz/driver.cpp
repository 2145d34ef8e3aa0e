// Side-by-side driver: animkit (through ak_part.c, C) and ozz-animation (here, C++), interleaved
// in one process. A copy of ../shared/peers/vs_ozz/driver.cpp (bench/vs_ozz/run.sh builds it)
// whose skinning rounds are long: per round and row, animkit and ozz runs alternate until each
// side has run ROUND_MS milliseconds (env AK_VS_OZZ_ROUND_MS, default 150) and at least REP
// times; the round's figure per side is its fastest run, in thread CPU time for one-thread rows
// (preemption on a loaded machine is not counted; AK_VS_OZZ_CLOCK=wall for wall time) and wall
// time for two threads, the round's ratio the ratio of the two. Reported: median over
// ROUNDS rounds, per-round ratio animkit/ozz (median, min-max) and its spread
// (max - min) / median of the per-round ratios, in percent (the +-15% criterion is spread <= 30%).
// The animation rows likewise run the implementations in turn, whole 4096-evaluation passes,
// until each has run AK_VS_OZZ_ANIM_MS, in thread CPU time; ratio = fastest pass / ozz's.
// AK_VS_OZZ_ANIM_MS (default 40) is the animation rows' time per implementation and round;
// AK_BENCH_QUICK=1 (make bench's quick mode) shortens both (10 ms, and REP runs).
// AK_VS_OZZ_ROWS=substring keeps only the skinning rows whose name contains it (e.g. "P+N");
// AK_VS_OZZ_ACCESS=seq skips the random-access animation rows.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "harness.h"
#include "ozz/animation/offline/animation_builder.h"
#include "ozz/animation/offline/raw_animation.h"
#include "ozz/animation/offline/raw_skeleton.h"
#include "ozz/animation/offline/skeleton_builder.h"
#include "ozz/animation/runtime/animation.h"
#include "ozz/animation/runtime/ik_two_bone_job.h"
#include "ozz/animation/runtime/local_to_model_job.h"
#include "ozz/animation/runtime/sampling_job.h"
#include "ozz/animation/runtime/skeleton.h"
#include "ozz/base/maths/simd_math.h"
#include "ozz/base/maths/simd_quaternion.h"
#include "ozz/base/maths/soa_transform.h"
#include "ozz/geometry/runtime/skinning_job.h"

static double wall() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
// Thread CPU time: time this thread ran, which preemption by other processes does not count (a
// shared, loaded machine); the one-thread rows use it unless AK_VS_OZZ_CLOCK=wall.
static bool CPU_CLOCK = true;
static double cpu() {
  if (!CPU_CLOCK) return wall();
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
static int ROUNDS = 11;
static int REP = 3;
static double ROUND_MS = 150;

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
struct Stat {
  std::vector<double> v;
  void add(double x) { v.push_back(x); }
  double med() const { return median(v); }
  double lo() const { return *std::min_element(v.begin(), v.end()); }
  double hi() const { return *std::max_element(v.begin(), v.end()); }
  double spread() const { return 100.0 * (hi() - lo()) / med(); }  // (max - min) / median, %
};

// ---------------- triad (float64, 3 x 256 MiB) ----------------
static const size_t TN = (256u << 20) / 8;
static double *ta, *tb, *tc;
static void triad_part(size_t b, size_t e, double s) {
  for (size_t i = b; i < e; ++i) ta[i] = tb[i] + s * tc[i];
}
static double triad(int threads) {  // GB/s, STREAM counting (24 B / element)
  double t0 = wall();
  if (threads == 1)
    triad_part(0, TN, 3.0);
  else {
    std::thread th(triad_part, TN / 2, TN, 3.0);
    triad_part(0, TN / 2, 3.0);
    th.join();
  }
  return 24.0 * TN / (wall() - t0) * 1e-9;
}

// ---------------- ozz skinning ----------------
static bool ozz_skin_range(const skin_data& d, bool normals, size_t b, size_t cnt) {
  ozz::geometry::SkinningJob job;
  const int K = d.K;
  job.vertex_count = (int)cnt;
  job.influences_count = K;
  job.joint_matrices = ozz::span<const ozz::math::Float4x4>(
      reinterpret_cast<const ozz::math::Float4x4*>(d.palette), 64);
  job.joint_indices = ozz::span<const uint16_t>(d.joints + b * K, cnt * K);
  job.joint_indices_stride = sizeof(uint16_t) * K;
  if (K > 1) {
    job.joint_weights = ozz::span<const float>(d.weights + b * K, cnt * K);
    job.joint_weights_stride = sizeof(float) * K;
  }
  job.in_positions = ozz::span<const float>(d.pos + 3 * b, 3 * cnt);
  job.in_positions_stride = 12;
  job.out_positions = ozz::span<float>(d.out_pos + 3 * b, 3 * cnt);
  job.out_positions_stride = 12;
  if (normals) {
    job.in_normals = ozz::span<const float>(d.nrm + 3 * b, 3 * cnt);
    job.in_normals_stride = 12;
    job.out_normals = ozz::span<float>(d.out_nrm + 3 * b, 3 * cnt);
    job.out_normals_stride = 12;
  }
  return job.Run();
}
static bool ozz_skin(const skin_data& d, bool normals, int threads) {
  if (threads == 1) return ozz_skin_range(d, normals, 0, d.n);
  bool ok2 = false;
  size_t h = d.n / 2;
  std::thread th([&] { ok2 = ozz_skin_range(d, normals, h, d.n - h); });
  bool ok1 = ozz_skin_range(d, normals, 0, h);
  th.join();
  return ok1 && ok2;
}

// ---------------- data ----------------
static float* aalloc(size_t nfloats) {
  size_t bytes = (nfloats * 4 + 63) & ~size_t(63);
  return (float*)aligned_alloc(64, bytes);
}

int main(int argc, char** argv) {
  size_t n = argc > 1 ? strtoull(argv[1], nullptr, 10) : 1000000;
  if (argc > 2) ROUNDS = atoi(argv[2]);
  if (getenv("REP")) REP = atoi(getenv("REP"));
  const bool quick = getenv("AK_BENCH_QUICK") && !strcmp(getenv("AK_BENCH_QUICK"), "1");  // make bench's quick mode
  if (quick) ROUND_MS = 10;
  if (getenv("AK_VS_OZZ_ROUND_MS")) ROUND_MS = atof(getenv("AK_VS_OZZ_ROUND_MS"));
  if (getenv("AK_VS_OZZ_CLOCK") && !strcmp(getenv("AK_VS_OZZ_CLOCK"), "wall")) CPU_CLOCK = false;
  const char* row_filter = getenv("AK_VS_OZZ_ROWS");
  const bool seq_only = getenv("AK_VS_OZZ_ACCESS") && !strcmp(getenv("AK_VS_OZZ_ACCESS"), "seq");
  const char* only = argc > 3 ? argv[3] : "sai";  // s: skinning, a: animation, i: ik
  printf("harness: %zu vertices, 64 joints, rounds %d, each skinning figure per round = fastest of >= %d runs and >= %.0f ms "
         "per side (%s for 1 thread, wall for 2), animation figures fastest of >= %d interleaved runs; skinning kernel "
         "animkit=%s\n",
         n, ROUNDS, REP, ROUND_MS, CPU_CLOCK ? "thread CPU time" : "wall", REP, akh_skin_kernel());
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> U(-1.f, 1.f), U01(0.f, 1.f);

  // triad arrays
  ta = (double*)aligned_alloc(64, TN * 8);
  tb = (double*)aligned_alloc(64, TN * 8);
  tc = (double*)aligned_alloc(64, TN * 8);
  for (size_t i = 0; i < TN; ++i) ta[i] = 0, tb[i] = (double)(i & 1023), tc[i] = 1.0;

  if (strchr(only, 's')) {
    // palette: 64 random rigid transforms, column-major
    float* pal = aalloc(64 * 16);
    for (int j = 0; j < 64; ++j) {
      ozz::math::Float3 axis(U(rng), U(rng), U(rng));
      axis = Normalize(axis);
      ozz::math::Quaternion q = ozz::math::Quaternion::FromAxisAngle(axis, 3.f * U(rng));
      float x = q.x, y = q.y, z = q.z, w = q.w;
      float* m = pal + 16 * j;
      m[0] = 1 - 2 * (y * y + z * z), m[1] = 2 * (x * y + z * w), m[2] = 2 * (x * z - y * w), m[3] = 0;
      m[4] = 2 * (x * y - z * w), m[5] = 1 - 2 * (x * x + z * z), m[6] = 2 * (y * z + x * w), m[7] = 0;
      m[8] = 2 * (x * z + y * w), m[9] = 2 * (y * z - x * w), m[10] = 1 - 2 * (x * x + y * y), m[11] = 0;
      m[12] = U(rng), m[13] = U(rng), m[14] = U(rng), m[15] = 1;
    }
    float* pos = aalloc(3 * n);
    float* nrm = aalloc(3 * n);
    float* ctr = aalloc(3 * n);
    float* op_ak = aalloc(3 * n);
    float* on_ak = aalloc(3 * n);
    float* op_oz = aalloc(3 * n);
    float* on_oz = aalloc(3 * n);
    for (size_t i = 0; i < n; ++i) {
      float x = U(rng), y = U(rng), z = U(rng);
      pos[3 * i] = x, pos[3 * i + 1] = y, pos[3 * i + 2] = z;
      ctr[3 * i] = 0.5f * x, ctr[3 * i + 1] = 0.5f * y, ctr[3 * i + 2] = 0.5f * z;
      float a = U(rng), b = U(rng), c = 1.f, l = 1.f / std::sqrt(a * a + b * b + c * c);
      nrm[3 * i] = a * l, nrm[3 * i + 1] = b * l, nrm[3 * i + 2] = c * l;
    }
    memset(op_ak, 0, 12 * n), memset(on_ak, 0, 12 * n), memset(op_oz, 0, 12 * n), memset(on_oz, 0, 12 * n);
    const int Ks[4] = {1, 2, 4, 8};
    std::vector<uint16_t*> J(9);
    std::vector<float*> W(9);
    for (int K : Ks) {
      J[K] = (uint16_t*)aligned_alloc(64, ((2 * K * n + 63) / 64) * 64);
      W[K] = aalloc(K * n);
      for (size_t i = 0; i < n; ++i) {
        float s = 0, w[8];
        for (int k = 0; k < K; ++k) w[k] = 0.05f + U01(rng), s += w[k];
        float acc = 0;
        for (int k = 0; k < K; ++k) {
          J[K][K * i + k] = (uint16_t)(rng() % 64);
          W[K][K * i + k] = k + 1 < K ? w[k] / s : 1.f - acc;
          acc += W[K][K * i + k];
        }
      }
    }
    auto data = [&](int K) {
      skin_data d = {n, K, pos, nrm, ctr, J[K], W[K], pal, op_ak, on_ak};
      return d;
    };
    // correctness first
    for (int K : Ks)
      for (int nm = 0; nm < 2; ++nm) {
        skin_data d = data(K);
        int v = akh_skin_validate(&d, 0, nm);
        int r = akh_skin(&d, 0, nm, 1);
        skin_data e = d;
        e.out_pos = op_oz, e.out_nrm = on_oz;
        bool ok = ozz_skin(e, nm, 1);
        double dp = 0, dn = 0, lenmax = 0, lenmin = 1e9;
        for (size_t i = 0; i < n; ++i)
          for (int c = 0; c < 3; ++c) dp = std::max(dp, (double)std::fabs(op_ak[3 * i + c] - op_oz[3 * i + c]));
        if (nm)
          for (size_t i = 0; i < n; ++i) {
            const float* o = on_oz + 3 * i;
            double l = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
            lenmax = std::max(lenmax, l), lenmin = std::min(lenmin, l);
            for (int c = 0; c < 3; ++c) dn = std::max(dn, std::fabs(on_ak[3 * i + c] - o[c] / l));
          }
        printf("  check K=%d %s: ak validate %d run %d, ozz run %d; max|dpos| %.2e", K, nm ? "P+N" : "P  ", v, r, ok, dp);
        if (nm) printf(", max|ak normal - normalized ozz normal| %.2e (ozz normal length %.3f..%.3f)", dn, lenmin, lenmax);
        printf("\n");
      }
    {
      skin_data d = data(4);
      printf("  check DQS validate %d, CoR validate %d\n", akh_skin_validate(&d, 1, 1), akh_skin_validate(&d, 2, 1));
    }

    struct Row {
      std::string name;
      int K, nm, method, threads;
      bool ozz;
      double bytes;
      Stat ak, oz, ratio;
    };
    std::vector<Row> rows;
    for (int K : Ks)
      for (int nm = 0; nm < 2; ++nm)
        rows.push_back({"LBS " + std::string(nm ? "P+N" : "P") + " K=" + std::to_string(K), K, nm, 0, 1, true,
                        (nm ? 48.0 : 24.0) + 6.0 * K});
    rows.push_back({"DQS P+N K=4", 4, 1, 1, 1, false, 72});
    rows.push_back({"CoR P+N K=4 (+12 B centers)", 4, 1, 2, 1, false, 84});
    rows.push_back({"2 thr LBS P K=4", 4, 0, 0, 2, true, 48});
    rows.push_back({"2 thr LBS P+N K=4", 4, 1, 0, 2, true, 72});
    rows.push_back({"2 thr DQS P+N K=4", 4, 1, 1, 2, false, 72});
    rows.push_back({"2 thr CoR P+N K=4", 4, 1, 2, 2, false, 84});
    if (row_filter && *row_filter) {
      std::vector<Row> kept;
      for (Row& r : rows)
        if (r.name.find(row_filter) != std::string::npos) kept.push_back(r);
      rows.swap(kept);
    }
    Stat tr1, tr2;
    for (int round = 0; round < ROUNDS; ++round) {
      tr1.add(std::max(triad(1), triad(1)));
      tr2.add(std::max(triad(2), triad(2)));
      for (Row& r : rows) {
        skin_data d = data(r.K);
        skin_data e = d;
        e.out_pos = op_oz, e.out_nrm = on_oz;
        double ba = 1e30, bo = 1e30, sa = 0, so = 0;
        auto clk = [&]() { return r.threads == 1 ? cpu() : wall(); };
        for (int k = 0; k < REP || sa < 1e-3 * ROUND_MS || (r.ozz && so < 1e-3 * ROUND_MS); ++k) {
          // alternate which library goes first, so neither always runs on a warm cache
          for (int side = 0; side < 2; ++side) {
            if ((side ^ (k & 1)) == 0) {
              double t0 = clk();
              if (akh_skin(&d, r.method, r.nm, r.threads) != 0) printf("ak fail\n");
              double t = clk() - t0;
              ba = std::min(ba, t), sa += t;
            } else if (r.ozz) {
              double t0 = clk();
              if (!ozz_skin(e, r.nm, r.threads)) printf("ozz fail\n");
              double t = clk() - t0;
              bo = std::min(bo, t), so += t;
            }
          }
        }
        r.ak.add(n / ba * 1e-6);
        if (r.ozz) r.oz.add(n / bo * 1e-6), r.ratio.add(bo / ba);  // ratio of rates ak/ozz, fastest runs
      }
    }
    printf("\nSKINNING (Mvert/s; median of %d rounds, [min-max]); ratio = animkit rate / ozz rate per round\n",
           ROUNDS);
    printf("triad 1 thread: %.1f GB/s [%.1f-%.1f]; 2 threads: %.1f GB/s [%.1f-%.1f]\n", tr1.med(), tr1.lo(), tr1.hi(),
           tr2.med(), tr2.lo(), tr2.hi());
    const double T1 = tr1.med(), T2 = tr2.med();
    printf("%-30s %5s %18s %8s %18s %8s %22s %8s\n", "workload", "B/v", "animkit", "%triad", "ozz", "%triad",
           "ak/ozz med [min-max]", "spread");
    for (Row& r : rows) {
      double T = r.threads == 2 ? T2 : T1;
      printf("%-30s %5.0f %7.1f [%5.1f-%5.1f] %7.0f%%", r.name.c_str(), r.bytes, r.ak.med(), r.ak.lo(), r.ak.hi(),
             100 * r.ak.med() * r.bytes * 1e-3 / T);
      if (r.ozz)
        printf(" %7.1f [%5.1f-%5.1f] %7.0f%% %6.2f [%.2f-%.2f] %6.1f%%", r.oz.med(), r.oz.lo(), r.oz.hi(),
               100 * r.oz.med() * r.bytes * 1e-3 / T, r.ratio.med(), r.ratio.lo(), r.ratio.hi(), r.ratio.spread());
      printf("\n");
    }
    // scaling: per-round ratio 2thr/1thr
    auto has = [&](const char* nm) {
      for (Row& r : rows)
        if (r.name == nm) return true;
      return false;
    };
    auto find = [&](const char* nm) -> Row& {
      for (Row& r : rows)
        if (r.name == nm) return r;
      return rows[0];
    };
    const char* pairs[4][2] = {{"LBS P K=4", "2 thr LBS P K=4"},
                               {"LBS P+N K=4", "2 thr LBS P+N K=4"},
                               {"DQS P+N K=4", "2 thr DQS P+N K=4"},
                               {"CoR P+N K=4 (+12 B centers)", "2 thr CoR P+N K=4"}};
    for (auto& p : pairs) {
      if (!has(p[0]) || !has(p[1])) continue;
      Row &a = find(p[0]), &b = find(p[1]);
      Stat s, so;
      for (int i = 0; i < ROUNDS; ++i) {
        s.add(b.ak.v[i] / a.ak.v[i]);
        if (a.ozz) so.add(b.oz.v[i] / a.oz.v[i]);
      }
      printf("scaling 2thr/1thr %-28s animkit x%.2f [%.2f-%.2f]", p[0], s.med(), s.lo(), s.hi());
      if (a.ozz) printf("  ozz x%.2f [%.2f-%.2f]", so.med(), so.lo(), so.hi());
      printf("\n");
    }
    Stat dq, cd;
    if (has("LBS P+N K=4") && has("DQS P+N K=4") && has("CoR P+N K=4 (+12 B centers)")) {
    for (int i = 0; i < ROUNDS; ++i)
      dq.add(find("LBS P+N K=4").ak.v[i] / find("DQS P+N K=4").ak.v[i]),
          cd.add(find("DQS P+N K=4").ak.v[i] / find("CoR P+N K=4 (+12 B centers)").ak.v[i]);
    printf("animkit time ratios: DQS/LBS(P+N) %.2f [%.2f-%.2f], CoR/DQS %.2f [%.2f-%.2f]\n", dq.med(), dq.lo(), dq.hi(),
           cd.med(), cd.lo(), cd.hi());
    }
    fflush(stdout);
  }

  // ---------------- animation: 60 joints ----------------
  if (strchr(only, 'a')) {
    const int NJ = 60, KEYS = 301;
    int parents[NJ];
    // humanoid-like, already depth-first: spine 0-3, neck 4, head 5, L arm 6-9 + 5 fingers x3 (10-24),
    // R arm 25-28 + fingers (29-43), L leg 44-47, R leg 48-51, tail 52-59
    for (int i = 0; i < NJ; ++i) parents[i] = i - 1;
    parents[0] = -1;
    parents[4] = 3;
    parents[6] = 3;
    for (int f = 0; f < 5; ++f) parents[10 + 3 * f] = 9;
    parents[25] = 3;
    for (int f = 0; f < 5; ++f) parents[29 + 3 * f] = 28;
    parents[44] = 0;
    parents[48] = 0;
    parents[52] = 0;
    std::vector<float> rest(3 * NJ), times(KEYS), T(NJ * KEYS * 3), R(NJ * KEYS * 4), S(NJ * KEYS * 3);
    for (int j = 0; j < NJ; ++j) rest[3 * j] = 0.1f * U(rng), rest[3 * j + 1] = 0.3f + 0.1f * U(rng), rest[3 * j + 2] = 0.05f * U(rng);
    for (int k = 0; k < KEYS; ++k) times[k] = k / 30.f;
    for (int j = 0; j < NJ; ++j) {
      float ax = U(rng), ay = U(rng), az = U(rng), al = std::sqrt(ax * ax + ay * ay + az * az);
      ax /= al, ay /= al, az /= al;
      float ph = 6.28f * U01(rng), fr = 0.2f + U01(rng);
      for (int k = 0; k < KEYS; ++k) {
        float t = times[k];
        float* tv = &T[(j * KEYS + k) * 3];
        for (int c = 0; c < 3; ++c) tv[c] = rest[3 * j + c] + 0.02f * std::sin(fr * 6.28f * t + ph + c) + 0.002f * U(rng);
        float ang = 0.8f * std::sin(fr * 6.28f * t + ph) + 0.02f * U(rng), s = std::sin(ang / 2), c = std::cos(ang / 2);
        float* q = &R[(j * KEYS + k) * 4];
        q[0] = ax * s, q[1] = ay * s, q[2] = az * s, q[3] = c;
        float* sv = &S[(j * KEYS + k) * 3];
        for (int cc = 0; cc < 3; ++cc) sv[cc] = 1.f + 0.03f * std::sin(fr * 3.f * t + cc);
      }
    }
    if (akh_anim_setup(NJ, parents, rest.data(), KEYS, times.data(), T.data(), R.data(), S.data(), 0) != 0) {
      printf("animkit anim setup failed\n");
      return 1;
    }
    // ozz skeleton
    using namespace ozz::animation;
    offline::RawSkeleton raw_sk;
    std::function<void(offline::RawSkeleton::Joint&, int)> fill = [&](offline::RawSkeleton::Joint& jt, int i) {
      char nm[8];
      snprintf(nm, sizeof nm, "j%02d", i);
      jt.name = nm;
      jt.transform = ozz::math::Transform::identity();
      jt.transform.translation = ozz::math::Float3(rest[3 * i], rest[3 * i + 1], rest[3 * i + 2]);
      int nc = 0;
      for (int c = i + 1; c < NJ; ++c) nc += parents[c] == i;
      jt.children.resize(nc);
      int k = 0;
      for (int c = i + 1; c < NJ; ++c)
        if (parents[c] == i) fill(jt.children[k++], c);
    };
    raw_sk.roots.resize(1);
    fill(raw_sk.roots[0], 0);
    auto skeleton = offline::SkeletonBuilder()(raw_sk);
    bool order_ok = skeleton->num_joints() == NJ;
    for (int i = 0; i < NJ && order_ok; ++i) {
      char nm[8];
      snprintf(nm, sizeof nm, "j%02d", i);
      order_ok = strcmp(skeleton->joint_names()[i], nm) == 0 && skeleton->joint_parents()[i] == parents[i];
    }
    offline::RawAnimation raw_an;
    raw_an.duration = 10.f;
    raw_an.tracks.resize(NJ);
    for (int j = 0; j < NJ; ++j)
      for (int k = 0; k < KEYS; ++k) {
        const float* tv = &T[(j * KEYS + k) * 3];
        const float* q = &R[(j * KEYS + k) * 4];
        const float* sv = &S[(j * KEYS + k) * 3];
        raw_an.tracks[j].translations.push_back({times[k], ozz::math::Float3(tv[0], tv[1], tv[2])});
        raw_an.tracks[j].rotations.push_back({times[k], ozz::math::Quaternion(q[0], q[1], q[2], q[3])});
        raw_an.tracks[j].scales.push_back({times[k], ozz::math::Float3(sv[0], sv[1], sv[2])});
      }
    offline::AnimationBuilder builder;
    auto anim0 = builder(raw_an);
    builder.iframe_interval = 1.f;
    auto anim1 = builder(raw_an);
    printf("\nANIMATION: %d joints, %d keys x T/R/S per joint, ozz skeleton order matches: %d, ozz runtime sizes %zu B "
           "(no iframes) / %zu B (iframes 1 s); animkit kernels: FK %s, sampling %s\n",
           NJ, KEYS, order_ok, anim0->size(), anim1->size(), akh_fk_kernel(), akh_sample_kernel());
    ozz::vector<ozz::math::SoaTransform> locals(skeleton->num_soa_joints());
    ozz::vector<ozz::math::Float4x4> models(skeleton->num_joints());
    SamplingJob::Context ctx0(NJ), ctx1(NJ);
    auto ozz_eval = [&](const Animation* an, SamplingJob::Context* ctx, float time, int fk) {
      if (fk != 2) {
        SamplingJob sj;
        sj.animation = an;
        sj.context = ctx;
        sj.ratio = time / 10.f;
        sj.output = ozz::make_span(locals);
        sj.Run();
      }
      if (fk) {
        LocalToModelJob lj;
        lj.skeleton = skeleton.get();
        lj.input = ozz::make_span(locals);
        lj.output = ozz::make_span(models);
        lj.Run();
      }
    };
    // correctness: model matrices at a few times
    {
      double dmax = 0;
      for (int s = 0; s < 50; ++s) {
        float t = 0.1999f * s;
        akh_anim_eval(0, t, 1, 1);
        ozz_eval(anim0.get(), &ctx0, t, 1);
        const float* am = akh_anim_model();
        for (int j = 0; j < NJ; ++j) {
          float m[16];
          for (int c = 0; c < 4; ++c) ozz::math::StorePtrU(models[j].cols[c], m + 4 * c);
          for (int e = 0; e < 16; ++e) dmax = std::max(dmax, (double)std::fabs(m[e] - am[16 * j + e]));
        }
      }
      printf("  check: max |model matrix element| difference animkit(slerp) vs ozz over 50 times: %.2e\n", dmax);
    }
    const int F = 4096;
    std::vector<float> seq(F), rnd(F);
    for (int f = 0; f < F; ++f) seq[f] = std::fmod(f / 60.f, 10.f), rnd[f] = 10.f * U01(rng) * 0.99999f;
    struct Impl {
      const char* name;
      int kind;  // 0 ak slerp cursor, 1 ak nlerp cursor, 2 ak nlerp bsearch, 3 ozz, 4 ozz iframes
    };
    const Impl impls[5] = {{"animkit LINEAR(slerp) cursor", 0}, {"animkit NLERP cursor", 1},
                           {"animkit NLERP no cursor", 2},       {"ozz (no iframes)", 3},
                           {"ozz (iframes 1 s)", 4}};
    const char* modes[3] = {"sample only", "FK only", "sample+FK"};
    // stats[access][mode][impl] in us/eval
    Stat st[2][3][5];      // us per evaluation: per round, the fastest chunk
    Stat rt[2][3][5][2];   // per round: median over reps of (impl chunk time / ozz chunk time), vs ozz and ozz-iframes
    // A rep runs the whole time sequence (C = F evaluations, 6.8 passes over the clip when
    // sequential) with every implementation, in an order rotated every rep; reps repeat until
    // every implementation has run ANIM_MS ms (and at least REP times).
    const int C = F;
    const double ANIM_MS = getenv("AK_VS_OZZ_ANIM_MS") ? atof(getenv("AK_VS_OZZ_ANIM_MS")) : quick ? 0.0 : 40.0;
    for (int round = 0; round < ROUNDS; ++round)
      for (int acc = 0; acc < (seq_only ? 1 : 2); ++acc)
        for (int mode = 0; mode < 3; ++mode) {
          const std::vector<float>& tm = acc == 0 ? seq : rnd;
          int fk = mode == 0 ? 0 : mode == 1 ? 2 : 1;
          std::vector<int> act;
          for (int ii = 0; ii < 5; ++ii)
            if (!(mode == 1 && (ii == 1 || ii == 2 || ii == 4))) act.push_back(ii);
          double best[5], spent[5];
          int pos[5] = {0, 0, 0, 0, 0};
          std::vector<double> times[5];
          for (int ii = 0; ii < 5; ++ii) best[ii] = 1e30, spent[ii] = 0;
          for (int rep = 0;; ++rep) {
            bool done = rep >= REP;
            for (int ii : act) done = done && spent[ii] >= 1e-3 * ANIM_MS;
            if (done) break;
            for (size_t o = 0; o < act.size(); ++o) {
              const int ii = act[(o + rep) % act.size()];
              const int f0 = pos[ii];
              double t0 = cpu();
              switch (impls[ii].kind) {
                case 0: for (int f = f0; f < f0 + C; ++f) akh_anim_eval(0, tm[f], 1, fk); break;
                case 1: for (int f = f0; f < f0 + C; ++f) akh_anim_eval(1, tm[f], 1, fk); break;
                case 2: for (int f = f0; f < f0 + C; ++f) akh_anim_eval(1, tm[f], 0, fk); break;
                case 3: for (int f = f0; f < f0 + C; ++f) ozz_eval(anim0.get(), &ctx0, tm[f], fk); break;
                case 4: for (int f = f0; f < f0 + C; ++f) ozz_eval(anim1.get(), &ctx1, tm[f], fk); break;
              }
              double t = cpu() - t0;
              best[ii] = std::min(best[ii], t), spent[ii] += t, times[ii].push_back(t);
            }
          }
          for (int ii : act) {
            st[acc][mode][ii].add(best[ii] / C * 1e6);
            for (int ref = 0; ref < 2; ++ref) {
              const int jj = ref == 0 ? 3 : 4;
              if (ii == jj || times[jj].empty()) continue;
              rt[acc][mode][ii][ref].add(best[ii] / best[jj]);
            }
          }
        }
    printf("us per evaluation of 60 joints (median of %d rounds [min-max] of each round's fastest %d-evaluation chunk); "
           "ratio = animkit time / ozz(no iframes) time: per round the ratio of the fastest chunks (implementations "
           "interleaved chunk by chunk); spread = (max - min) / median of the rounds' ratios; %s\n",
           ROUNDS, C, CPU_CLOCK ? "thread CPU time" : "wall time");
    for (int acc = 0; acc < 2; ++acc)
      for (int mode = 0; mode < 3; ++mode)
        for (int ii = 0; ii < 5; ++ii) {
          const Stat& s = st[acc][mode][ii];
          if (s.v.empty()) continue;
          printf("  %-10s %-12s %-30s %8.3f [%.3f-%.3f]", acc ? "random" : "sequential", modes[mode], impls[ii].name,
                 s.med(), s.lo(), s.hi());
          if (ii != 3) {
            const Stat& r = rt[acc][mode][ii][0];
            printf("  time vs ozz x%.2f [%.2f-%.2f] spread %.0f%%", r.med(), r.lo(), r.hi(), r.spread());
          }
          if (ii < 3 && !rt[acc][mode][ii][1].v.empty()) {
            const Stat& r = rt[acc][mode][ii][1];
            printf("  vs ozz-iframes x%.2f [%.2f-%.2f]", r.med(), r.lo(), r.hi());
          }
          printf("\n");
        }
    fflush(stdout);
  }

  // ---------------- two-bone IK ----------------
  if (strchr(only, 'i')) {
    using namespace ozz::math;
    // limb: start at origin rotated 0.3 rad about z; mid at 1 along start x, bent 0.6 rad about z; end 1 further.
    Float4x4 start = Float4x4::FromAffine(simd_float4::zero(), simd_float4::Load(0, 0, std::sin(0.15f), std::cos(0.15f)),
                                          simd_float4::one());
    Float4x4 midl = Float4x4::FromAffine(simd_float4::Load(1, 0, 0, 0), simd_float4::Load(0, 0, std::sin(0.3f), std::cos(0.3f)),
                                         simd_float4::one());
    Float4x4 endl = Float4x4::FromAffine(simd_float4::Load(1, 0, 0, 0), simd_float4::Load(0, 0, 0, 1), simd_float4::one());
    Float4x4 mid = start * midl, end = mid * endl;
    float fs[16], fm[16], fe[16];
    for (int c = 0; c < 4; ++c) StorePtrU(start.cols[c], fs + 4 * c), StorePtrU(mid.cols[c], fm + 4 * c), StorePtrU(end.cols[c], fe + 4 * c);
    const float pole[3] = {0, 1, 0}, axis[3] = {0, 0, 1};
    const int NT = 4096;
    std::vector<float> tg(3 * NT), out(8 * NT);
    for (int i = 0; i < NT; ++i) {
      float x, y, z, l;
      do x = U(rng), y = U(rng), z = U(rng), l = std::sqrt(x * x + y * y + z * z); while (l > 1 || l < 0.1f);
      float r = 0.2f + 1.7f * U01(rng);
      tg[3 * i] = x / l * r, tg[3 * i + 1] = y / l * r, tg[3 * i + 2] = z / l * r;
    }
    SimdQuaternion qs, qm;
    bool reached;
    auto ozz_solve = [&](const float* t) {
      ozz::animation::IKTwoBoneJob job;
      job.target = simd_float4::Load(t[0], t[1], t[2], 0);
      job.pole_vector = simd_float4::Load(pole[0], pole[1], pole[2], 0);
      job.mid_axis = simd_float4::Load(axis[0], axis[1], axis[2], 0);
      job.soften = 1.f;
      job.weight = 1.f;
      job.start_joint = &start;
      job.mid_joint = &mid;
      job.end_joint = &end;
      job.start_joint_correction = &qs;
      job.mid_joint_correction = &qm;
      job.reached = &reached;
      job.Run();
    };
    // agreement check
    {
      akh_ik_setup(fs, fm, fe, pole, axis);
      double worst = 0;
      int agree = 0, ozz_reached = 0;
      double ea = 0, eo = 0, pa = 0, po = 0;  // worst effector error; mean mid-joint height along pole
      auto eff = [&](const float* q1, const float* q2, SimdFloat4* midp) {
        Float4x4 Sm = start * Float4x4::FromQuaternion(simd_float4::LoadPtrU(q1));
        Float4x4 Mm = Sm * (Invert(start) * mid) * Float4x4::FromQuaternion(simd_float4::LoadPtrU(q2));
        Float4x4 Em = Mm * (Invert(mid) * end);
        *midp = Mm.cols[3];
        return Em.cols[3];
      };
      for (int i = 0; i < NT; ++i) {
        float a[4], b[4], c[4], d[4];
        akh_ik_solve(&tg[3 * i], a, b);
        ozz_solve(&tg[3 * i]);
        StorePtrU(qs.xyzw, c), StorePtrU(qm.xyzw, d);
        double d1 = std::fabs(a[0] * c[0] + a[1] * c[1] + a[2] * c[2] + a[3] * c[3]);
        double d2 = std::fabs(b[0] * d[0] + b[1] * d[1] + b[2] * d[2] + b[3] * d[3]);
        worst = std::max(worst, std::max(1 - d1, 1 - d2));
        agree += std::max(1 - d1, 1 - d2) < 1e-4;
        {
          SimdFloat4 ma, mo;
          float e1[4], e2[4], m1[4], m2[4];
          StorePtrU(eff(a, b, &ma), e1), StorePtrU(eff(c, d, &mo), e2), StorePtrU(ma, m1), StorePtrU(mo, m2);
          const float* t = &tg[3 * i];
          ea = std::max(ea, (double)std::sqrt((e1[0]-t[0])*(e1[0]-t[0])+(e1[1]-t[1])*(e1[1]-t[1])+(e1[2]-t[2])*(e1[2]-t[2])));
          eo = std::max(eo, (double)std::sqrt((e2[0]-t[0])*(e2[0]-t[0])+(e2[1]-t[1])*(e2[1]-t[1])+(e2[2]-t[2])*(e2[2]-t[2])));
          pa += m1[1] / NT, po += m2[1] / NT;
        }
        ozz_reached += reached;
      }
      printf("\n  IK agreement: %d of %d targets agree within 1e-4 (1-|dot|); ozz reports %d reached; worst effector-target distance animkit %.2e ozz %.2e (corrections applied as local post-multiplied rotations); mean mid-joint y: animkit %.3f ozz %.3f", agree, NT, ozz_reached, ea, eo, pa, po);
      printf("\nTWO-BONE IK: %d targets; check: max (1 - |dot|) between animkit and ozz corrections (mid_axis z, pole y): %.2e\n",
             NT, worst);
    }
    Stat a_axis, a_noaxis, a_many, oz, r1, r2, r3;
    for (int round = 0; round < ROUNDS; ++round) {
      double b1 = 1e30, b2 = 1e30, b3 = 1e30, bo = 1e30;
      float qa[4], qb[4];
      for (int rep = 0; rep < REP; ++rep) {
        double t0 = wall();
        akh_ik_setup(fs, fm, fe, pole, axis);
        for (int i = 0; i < NT; ++i) akh_ik_solve(&tg[3 * i], qa, qb);
        double t1 = wall();
        for (int i = 0; i < NT; ++i) ozz_solve(&tg[3 * i]);
        double t2 = wall();
        akh_ik_setup(fs, fm, fe, pole, nullptr);
        for (int i = 0; i < NT; ++i) akh_ik_solve(&tg[3 * i], qa, qb);
        double t3 = wall();
        akh_ik_solve_many(tg.data(), NT, out.data());
        double t4 = wall();
        b1 = std::min(b1, t1 - t0), bo = std::min(bo, t2 - t1), b2 = std::min(b2, t3 - t2), b3 = std::min(b3, t4 - t3);
      }
      a_axis.add(b1 / NT * 1e9), oz.add(bo / NT * 1e9), a_noaxis.add(b2 / NT * 1e9), a_many.add(b3 / NT * 1e9);
      r1.add(b1 / bo), r2.add(b2 / bo), r3.add(b3 / bo);
    }
    printf("ns per solve (median of %d rounds [min-max]); time ratio animkit/ozz per round:\n", ROUNDS);
    printf("  ozz IKTwoBoneJob (job set up per call)      %7.1f [%.1f-%.1f]\n", oz.med(), oz.lo(), oz.hi());
    printf("  animkit two_bone_run, mid_axis z            %7.1f [%.1f-%.1f]  x%.2f [%.2f-%.2f]\n", a_axis.med(), a_axis.lo(),
           a_axis.hi(), r1.med(), r1.lo(), r1.hi());
    printf("  animkit two_bone_run, mid_axis 0 (plane)    %7.1f [%.1f-%.1f]  x%.2f [%.2f-%.2f]\n", a_noaxis.med(),
           a_noaxis.lo(), a_noaxis.hi(), r2.med(), r2.lo(), r2.hi());
    printf("  animkit two_bone_run_many (64/batch, axis 0)%7.1f [%.1f-%.1f]  x%.2f [%.2f-%.2f]\n", a_many.med(),
           a_many.lo(), a_many.hi(), r3.med(), r3.lo(), r3.hi());
  }
  return 0;
}
