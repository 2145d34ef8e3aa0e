/* A game's animation frame: 1,000 characters (half builtin:humanoid, half CesiumMan), each
 * with its own clip and time, sampled, FK'd and skinned (LBS with normals) every frame, the
 * characters split over the library's worker team (bench/crowd_frame.h).
 *     bench_crowd_frame [--threads 1,2,4,8,16] [--frames N] [--characters N] [--phases]
 *                       [--schedule static|dynamic]
 * Default threads: 1, 2, 4, ... up to the cores online (and that count itself), so `make bench`
 * on a 16-core machine measures 1, 2, 4, 8 and 16 threads. Defaults: 60 frames, 1,000
 * characters (AK_BENCH_QUICK: 6 frames, 100 characters).
 * Characters alternate between builtin:humanoid (clips "walk", "wave") and CesiumMan
 * ($ANIMKIT_ASSETS/gltf/CesiumMan/glTF-Binary/CesiumMan.glb, default ../shared/assets; its one
 * clip); without CesiumMan every character is a humanoid (said on stdout). Character i plays
 * clip (i / 2) mod the model's clip count from a fixed-seed random offset, advancing 1/60 s a
 * frame. --schedule (bench/crowd_frame.h): static, contiguous ranges of equal estimated cost,
 * one per thread (the default), or dynamic, chunks of 4 characters from a shared counter. The
 * skin data is validated once (frame 0); frames after that skip the O(n) check.
 *
 * Per thread count T (the list starts with 1, the reference): the median wall ms per frame over
 * N frames after 2 warm-up frames, frames per second (1000 / that), the process CPU ms per
 * frame (all threads), the speed-up and efficiency of the wall time over 1 thread, the GB/s of
 * skinned positions and normals written (every character has its own output buffers: about
 * 147 MB a frame for 1,000 characters, more than any cache, so this is the memory traffic that
 * may bound the scaling on many cores), and the hash (FNV-1a 64) of every character's positions and normals after the last frame: the same
 * for every T (else "DIFFERS" and exit code 1).
 * Then the CPU-time profile of src/tasks.h per T (akp_tasks_profile_step per frame, 6 frames):
 * CPU ms per frame, its serial part (the caller's work outside the parallel section, plus the
 * busiest thread's excess over the others' mean), the parallel part, the critical path (the
 * busiest thread's CPU), Amdahl's efficiency at 16 threads for the serial fraction measured at
 * T, 1-thread CPU / (T x critical path): what T free cores would give (neither sees memory
 * bandwidth or wake-ups; docs/BENCHMARKS.md "Predicted 16-thread efficiency from a CPU-time
 * profile per phase"), and the static partition's estimated imbalance (the largest range's
 * estimated cost over the mean, less 1; the dynamic schedule has none to estimate). --phases
 * lists each phase of every T > 1. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_clock.h"
#include "crowd_frame.h"

#define MAX_COUNTS 16

static bool parse_list(char* s, uint32_t* out, int* out_n) {
    *out_n = 0;
    for (char* p = s; *p && *out_n < MAX_COUNTS;) {
        const long v = strtol(p, &p, 10);
        if (v < 1 || v > (long)AKP_TASKS_MAX) return false;
        out[(*out_n)++] = (uint32_t)v;
        if (*p == ',') ++p;
        else if (*p) return false;
    }
    return *out_n > 0;
}

typedef struct cpu_profile {
    double serial_ms, parallel_ms, critical_ms; /* per frame */
    size_t phase_count;
    akp_phase_cpu phases[AKP_PHASES_MAX];
} cpu_profile;

/* The static partition's estimated imbalance on T threads: the largest range's estimated cost
 * over the mean, less 1 (what the partition alone costs the critical path). */
static double estimated_imbalance(const crowd* c, uint32_t T) {
    double worst = 0.0;
    for (uint32_t t = 0; t < T; ++t) {
        const double w = c->cost_prefix[crowd_split(c, t + 1, T)] - c->cost_prefix[crowd_split(c, t, T)];
        if (w > worst) worst = w;
    }
    return worst / (c->cost_prefix[c->count] / T) - 1.0;
}

/* frames profiled frames starting at *frame on T threads. */
static bool profile_cpu(crowd* c, uint64_t* frame, uint32_t T, int frames, cpu_profile* out) {
    bool ok = crowd_frame(c, (*frame)++, T, false); /* warm-up */
    akp_tasks_profile_enable(true);
    for (int s = 0; s < frames; ++s) {
        akp_tasks_profile_step();
        ok = crowd_frame(c, (*frame)++, T, false) && ok;
    }
    out->phase_count = akp_tasks_profile_phases(out->phases, AKP_PHASES_MAX);
    akp_tasks_profile_enable(false);
    out->serial_ms = out->parallel_ms = out->critical_ms = 0.0;
    for (size_t k = 0; k < out->phase_count; ++k) {
        akp_phase_cpu* p = &out->phases[k];
        p->serial_s *= 1e3 / frames, p->parallel_s *= 1e3 / frames, p->critical_s *= 1e3 / frames;
        out->serial_ms += p->serial_s, out->parallel_ms += p->parallel_s, out->critical_ms += p->critical_s;
    }
    return ok;
}

int main(int argc, char** argv) {
    uint32_t counts[MAX_COUNTS] = {1};
    int count_n = 1, frames = 60;
    const long cores = sysconf(_SC_NPROCESSORS_ONLN);
    for (uint32_t t = 2; (long)t <= cores && t <= AKP_TASKS_MAX && count_n < MAX_COUNTS - 1; t *= 2) counts[count_n++] = t;
    if (cores > 1 && (long)counts[count_n - 1] != cores && cores <= (long)AKP_TASKS_MAX) counts[count_n++] = (uint32_t)cores;
    size_t characters = 1000;
    bool phases = false, dynamic = false;
    if (bench_quick()) frames = 6, characters = 100;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            if (!parse_list(argv[++i], counts, &count_n)) {
                fprintf(stderr, "bench_crowd_frame: --threads takes a list of 1..%u\n", AKP_TASKS_MAX);
                return 2;
            }
        } else if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
            frames = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--characters") == 0 && i + 1 < argc) {
            characters = (size_t)strtoull(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--schedule") == 0 && i + 1 < argc) {
            ++i;
            if (strcmp(argv[i], "static") != 0 && strcmp(argv[i], "dynamic") != 0) {
                fprintf(stderr, "bench_crowd_frame: --schedule static or dynamic\n");
                return 2;
            }
            dynamic = strcmp(argv[i], "dynamic") == 0;
        } else if (strcmp(argv[i], "--phases") == 0) {
            phases = true;
        } else {
            fprintf(stderr, "usage: bench_crowd_frame [--threads 1,2,4,8,16] [--frames N] [--characters N] [--phases] "
                            "[--schedule static|dynamic]\n");
            return 2;
        }
    }
    if (counts[0] != 1 || frames < 1 || characters < 1) {
        fprintf(stderr, "bench_crowd_frame: the thread list starts with 1 (the reference); frames, characters >= 1\n");
        return 2;
    }
    char path[1024];
    const char* env = getenv("ANIMKIT_ASSETS");
    snprintf(path, sizeof path, "%s/gltf/CesiumMan/glTF-Binary/CesiumMan.glb",
             env && *env ? env : AK_SOURCE_DIR "/../shared/assets");
    crowd c;
    bool missing = false;
    if (!crowd_init(&c, characters, path, &missing)) {
        printf("SKIP: could not set up the crowd (no memory, or builtin:humanoid failed)\n");
        return 0;
    }
    c.dynamic = dynamic;
    size_t verts = 0;
    for (size_t i = 0; i < c.count; ++i) verts += c.chars[i].m->mesh->vertex_count;
    printf("crowd frame (%s schedule): %zu characters, %zu skinned vertices a frame", dynamic ? "dynamic" : "static",
           c.count, verts);
    for (int k = 0; k < c.model_count; ++k)
        printf("%s %s (%zu vertices, %zu joints, %zu clips)", k ? "," : ":", c.models[k].scene->name,
               c.models[k].mesh->vertex_count, c.models[k].joints, c.models[k].scene->clip_count);
    printf("\n");
    if (missing) printf("CesiumMan not found at %s (set ANIMKIT_ASSETS): builtin:humanoid only\n", path);
    if (!crowd_frame(&c, 0, 1, true)) {
        printf("FAIL: frame 0 (with the data check) failed\n");
        crowd_fini(&c);
        return 1;
    }
    /* each model's measured CPU per character beside the partition's estimate (one serial frame) */
    {
        double us[2] = {0, 0}, est[2] = {0, 0};
        size_t n[2] = {0, 0};
        for (size_t i = 0; i < c.count; ++i) {
            const int k = (int)(c.chars[i].m - c.models);
            const double t0 = bench_cpu_s();
            crowd_character_frame(&c.chars[i], 1, false);
            us[k] += (bench_cpu_s() - t0) * 1e6, est[k] += crowd_character_cost(&c.chars[i]), n[k]++;
        }
        printf("CPU per character (1 thread, one frame):");
        for (int k = 0; k < c.model_count; ++k)
            if (n[k]) printf("%s %s %.1f us (estimate %.0f units, %.2f ns a unit)", k ? "," : "", c.models[k].scene->name,
                             us[k] / n[k], est[k] / n[k], 1e3 * us[k] / est[k]);
        printf("\n");
    }
    printf("median wall ms per frame over %d frames after 2 warm-up frames; cpu: process CPU ms per frame\n", frames);
    const double out_gb = (double)verts * 2.0 * sizeof(ak_vec3) * 1e-9; /* positions and normals written a frame */
    printf("%7s %10s %9s %10s %8s %6s %9s %16s\n", "threads", "wall ms", "fps", "cpu ms", "speedup", "eff", "out GB/s",
           "hash");
    double* t = malloc((size_t)frames * sizeof *t);
    if (!t) return 1;
    double ms1 = 0.0;
    uint64_t hash1 = 0;
    int rc = 0;
    for (int k = 0; k < count_n; ++k) {
        const uint32_t T = counts[k];
        bool ok = crowd_frame(&c, 1, T, false) && crowd_frame(&c, 2, T, false);
        const double cpu0 = bench_proc_s();
        for (int f = 0; f < frames; ++f) {
            const double t0 = bench_wall_s();
            ok = crowd_frame(&c, (uint64_t)f + 3, T, false) && ok;
            t[f] = (bench_wall_s() - t0) * 1e3;
        }
        const double cpu_ms = (bench_proc_s() - cpu0) * 1e3 / frames;
        const double ms = bench_percentile(t, (size_t)frames, 0.5);
        const uint64_t h = crowd_hash(&c);
        if (k == 0) ms1 = ms, hash1 = h;
        const bool same = h == hash1;
        if (!same || !ok) rc = 1;
        printf("%7u %10.3f %9.1f %10.3f %7.2fx %5.0f%% %9.1f %016llx%s%s\n", T, ms, 1e3 / ms, cpu_ms, ms1 / ms,
               100.0 * ms1 / ms / T, out_gb / (ms * 1e-3), (unsigned long long)h, same ? "" : " DIFFERS", ok ? "" : " (a frame failed)");
        fflush(stdout);
    }
    free(t);
    /* the CPU-time profile */
    cpu_profile* pr = malloc(sizeof *pr);
    if (!pr) return 1;
    const int pf = frames < 6 ? frames : 6;
    uint64_t frame = 1000;
    profile_cpu(&c, &frame, 1, pf, pr);
    const double cpu1 = pr->serial_ms + pr->parallel_ms;
    printf("cpu profile (src/tasks.h), %d frames per thread count: CPU ms per frame summed over threads\n", pf);
    printf("%7s %9s %9s %9s %9s %9s %10s %9s\n", "threads", "cpu ms", "serial", "parallel", "critical", "amdahl16",
           "critical T", "est. imb");
    printf("%7u %9.3f %9.3f %9.3f %9.3f\n", 1u, cpu1, pr->serial_ms, pr->parallel_ms, pr->critical_ms);
    for (int k = 0; k < count_n; ++k) {
        const uint32_t T = counts[k];
        if (T < 2) continue;
        const bool ok = profile_cpu(&c, &frame, T, pf, pr);
        const double total = pr->serial_ms + pr->parallel_ms;
        const double sf = total > 0.0 ? pr->serial_ms / total : 0.0;
        const double amdahl = 1.0 / (16.0 * (sf + (1.0 - sf) / 16.0));
        const double crit = pr->critical_ms > 0.0 ? cpu1 / (T * pr->critical_ms) : 0.0;
        char imb[32] = "-";
        if (!c.dynamic) snprintf(imb, sizeof imb, "%.2f%%", 100.0 * estimated_imbalance(&c, T));
        printf("%7u %9.3f %9.3f %9.3f %9.3f %8.1f%% %9.1f%% %9s%s\n", T, total, pr->serial_ms, pr->parallel_ms,
               pr->critical_ms, 100.0 * amdahl, 100.0 * crit, imb, ok ? "" : "  (a frame failed)");
        if (phases) {
            for (size_t i = 0; i < pr->phase_count; ++i) {
                const akp_phase_cpu* p = &pr->phases[i];
                printf("        phase %zu x%-2u serial %8.3f ms  parallel %8.3f ms  critical %8.3f ms\n", i, p->threads,
                       p->serial_s, p->parallel_s, p->critical_s);
            }
        }
        fflush(stdout);
    }
    free(pr);
    crowd_fini(&c);
    if (rc) printf("FAIL: a frame failed or the hash differs between thread counts\n");
    return rc;
}
