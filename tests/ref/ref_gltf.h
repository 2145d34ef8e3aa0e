/* An independent glTF 2.0 document reader for tests: the file's JSON (cJSON), GLB chunks,
 * data: URIs and external buffers, and plain accessors, written without the loader under test
 * so tests can compare the loader's results with the file's own data. Header-only: include it
 * in one test file. */
#ifndef ANIMKIT_REF_GLTF_H
#define ANIMKIT_REF_GLTF_H

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
#define REF_UNUSED __attribute__((unused))
#else
#define REF_UNUSED
#endif

/* ---- small helpers ------------------------------------------------------------------- */

static REF_UNUSED uint8_t* slurp(const char* path, size_t* size) {
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t* d = (uint8_t*)malloc((size_t)n + 1);
    if (d && fread(d, 1, (size_t)n, f) != (size_t)n) {
        free(d);
        d = NULL;
    }
    fclose(f);
    if (d) d[n] = 0;
    *size = (size_t)n;
    return d;
}

static const char k_b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static REF_UNUSED char* b64_encode(const void* data, size_t n) {
    const uint8_t* p = (const uint8_t*)data;
    char* out = (char*)malloc(4 * ((n + 2) / 3) + 1);
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        out[o++] = k_b64[v >> 18];
        out[o++] = k_b64[(v >> 12) & 63];
        out[o++] = i + 1 < n ? k_b64[(v >> 6) & 63] : '=';
        out[o++] = i + 2 < n ? k_b64[v & 63] : '=';
    }
    out[o] = 0;
    return out;
}

static REF_UNUSED uint8_t* b64_decode(const char* s, size_t* out_n) {
    size_t n = strlen(s);
    uint8_t* d = (uint8_t*)malloc(n + 1);
    uint32_t acc = 0;
    int bits = 0;
    size_t o = 0;
    for (size_t i = 0; i < n && s[i] != '='; ++i) {
        const char* q = strchr(k_b64, s[i]);
        if (!q) break;
        acc = acc << 6 | (uint32_t)(q - k_b64);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            d[o++] = (uint8_t)(acc >> bits);
        }
    }
    *out_n = o;
    return d;
}

/* ---- an independent glTF document reader (float accessors without sparse only) ---------- */

typedef struct doc {
    cJSON* root;
    uint8_t* file;
    uint8_t* bufs[16];
    size_t buf_size[16];
    const uint8_t* buf_ptr[16];
} doc;

static REF_UNUSED bool doc_open(doc* d, const char* path) {
    memset(d, 0, sizeof *d);
    size_t size = 0;
    d->file = slurp(path, &size);
    if (!d->file) return false;
    const char* json = (const char*)d->file;
    size_t json_len = size;
    const uint8_t* bin = NULL;
    size_t bin_len = 0;
    if (size > 20 && memcmp(d->file, "glTF", 4) == 0) {
        uint32_t jl;
        memcpy(&jl, d->file + 12, 4);
        json = (const char*)d->file + 20;
        json_len = jl;
        if (20 + jl + 8 <= size) {
            uint32_t bl;
            memcpy(&bl, d->file + 20 + jl, 4);
            bin = d->file + 28 + jl;
            bin_len = bl;
        }
    }
    d->root = cJSON_ParseWithLength(json, json_len);
    if (!d->root) return false;
    cJSON* buffers = cJSON_GetObjectItem(d->root, "buffers");
    int i = 0;
    cJSON* b;
    cJSON_ArrayForEach(b, buffers) {
        if (i >= 16) break;
        cJSON* uri = cJSON_GetObjectItem(b, "uri");
        if (!uri) {
            d->buf_ptr[i] = bin;
            d->buf_size[i] = bin_len;
        } else if (strncmp(uri->valuestring, "data:", 5) == 0) {
            d->bufs[i] = b64_decode(strchr(uri->valuestring, ',') + 1, &d->buf_size[i]);
            d->buf_ptr[i] = d->bufs[i];
        } else {
            char p[1024];
            const char* slash = strrchr(path, '/');
            snprintf(p, sizeof p, "%.*s/%s", (int)(slash - path), path, uri->valuestring);
            d->bufs[i] = slurp(p, &d->buf_size[i]);
            d->buf_ptr[i] = d->bufs[i];
        }
        ++i;
    }
    return true;
}

static REF_UNUSED void doc_close(doc* d) {
    cJSON_Delete(d->root);
    free(d->file);
    for (int i = 0; i < 16; ++i) free(d->bufs[i]);
}

static REF_UNUSED cJSON* jget(const cJSON* o, const char* key) { return cJSON_GetObjectItemCaseSensitive(o, key); }
static REF_UNUSED int jint(const cJSON* o, const char* key, int dflt) {
    const cJSON* v = jget(o, key);
    return cJSON_IsNumber(v) ? v->valueint : dflt;
}
static REF_UNUSED int jsize(const cJSON* o, const char* key) {
    const cJSON* v = jget(o, key);
    return cJSON_IsArray(v) ? cJSON_GetArraySize(v) : 0;
}
static REF_UNUSED cJSON* jat(const cJSON* o, const char* key, int i) { return cJSON_GetArrayItem(jget(o, key), i); }

static REF_UNUSED int accessor_count(const doc* d, int ai) { return jint(jat(d->root, "accessors", ai), "count", -1); }

/* Float accessor (no sparse) into out[count * comps]; false when not plain floats. */
static REF_UNUSED bool doc_floats(const doc* d, int ai, int comps, float* out) {
    const cJSON* a = jat(d->root, "accessors", ai);
    if (!a || jget(a, "sparse") || jint(a, "componentType", 0) != 5126) return false;
    const cJSON* v = jat(d->root, "bufferViews", jint(a, "bufferView", -1));
    if (!v) return false;
    int stride = jint(v, "byteStride", comps * 4);
    size_t off = (size_t)jint(v, "byteOffset", 0) + (size_t)jint(a, "byteOffset", 0);
    int bi = jint(v, "buffer", 0);
    int n = jint(a, "count", 0);
    if (!d->buf_ptr[bi] || off + (size_t)(n - 1) * (size_t)stride + (size_t)comps * 4 > d->buf_size[bi]) return false;
    for (int i = 0; i < n; ++i) memcpy(out + (size_t)i * comps, d->buf_ptr[bi] + off + (size_t)i * stride, (size_t)comps * 4);
    return true;
}

/* Accessor of unsigned integers (UNSIGNED_BYTE / SHORT / INT, no sparse, not normalized) into
 * out[count * comps]; false for other types. */
static REF_UNUSED bool doc_uints(const doc* d, int ai, int comps, uint32_t* out) {
    const cJSON* a = jat(d->root, "accessors", ai);
    if (!a || jget(a, "sparse")) return false;
    int ct = jint(a, "componentType", 0);
    int size = ct == 5121 ? 1 : ct == 5123 ? 2 : ct == 5125 ? 4 : 0;
    if (!size) return false;
    const cJSON* v = jat(d->root, "bufferViews", jint(a, "bufferView", -1));
    if (!v) return false;
    int stride = jint(v, "byteStride", comps * size);
    size_t off = (size_t)jint(v, "byteOffset", 0) + (size_t)jint(a, "byteOffset", 0);
    int bi = jint(v, "buffer", 0);
    int n = jint(a, "count", 0);
    if (!d->buf_ptr[bi] || off + (size_t)(n - 1) * (size_t)stride + (size_t)(comps * size) > d->buf_size[bi]) return false;
    for (int i = 0; i < n; ++i)
        for (int c = 0; c < comps; ++c) {
            const uint8_t* p = d->buf_ptr[bi] + off + (size_t)i * (size_t)stride + (size_t)(c * size);
            uint32_t x = 0;
            if (size == 1) x = p[0];
            else if (size == 2) x = (uint32_t)p[0] | (uint32_t)p[1] << 8;
            else x = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
            out[(size_t)i * comps + c] = x;
        }
    return true;
}

/* Number of components of an accessor's type ("SCALAR" 1 .. "MAT4" 16; 0 when unknown). */
static REF_UNUSED int accessor_comps(const doc* d, int ai) {
    const cJSON* t = jget(jat(d->root, "accessors", ai), "type");
    if (!cJSON_IsString(t)) return 0;
    static const char* const names[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
    static const int comps[] = {1, 2, 3, 4, 4, 9, 16};
    for (int i = 0; i < 7; ++i)
        if (strcmp(t->valuestring, names[i]) == 0) return comps[i];
    return 0;
}

/* Column-major double 4x4 product out = a * b (out may alias either input). */
static REF_UNUSED void ref_mat4d_mul(const double* a, const double* b, double* out) {
    double r[16];
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i < 4; ++i) {
            double acc = 0;
            for (int k = 0; k < 4; ++k) acc += a[k * 4 + i] * b[c * 4 + k];
            r[c * 4 + i] = acc;
        }
    memcpy(out, r, sizeof r);
}

#endif
