/* core: result strings, rng determinism and range. */
#include <stdint.h>

#include <animkit/core.h>

#include "ak_test.h"

AK_TEST(result_strings_never_null) {
    for (int i = -3; i < AK_RESULT_COUNT + 3; ++i) {
        const char* s = ak_result_string((ak_result)i);
        AK_CHECK(s != NULL && s[0] != '\0');
        AK_CHECK(ak_result_name((ak_result)i) != NULL);
    }
    AK_CHECK_STREQ(ak_result_string(AK_OK), "success");
    AK_CHECK_STREQ(ak_result_name(AK_ERR_BAD_DATA), "AK_ERR_BAD_DATA");
    AK_CHECK_STREQ(ak_result_string((ak_result)9999), "unknown result");
}

AK_TEST(rng_reproducible_and_uniform) {
    ak_rng a = ak_rng_make(7), b = ak_rng_make(7), c = ak_rng_make(8);
    int same = 1, differs = 0;
    double sum = 0.0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        uint32_t x = ak_rng_u32(&a), y = ak_rng_u32(&b), z = ak_rng_u32(&c);
        same &= x == y;
        differs |= x != z;
        float f = ak_rng_float(&a);
        (void)ak_rng_float(&b);
        AK_CHECK(f >= 0.0f && f < 1.0f);
        sum += f;
    }
    AK_CHECK(same);
    AK_CHECK(differs);
    /* mean of n uniforms: standard error 1/sqrt(12 n) ~ 0.0009; 5 sigma */
    AK_CHECK_NEAR(sum / n, 0.5, 0.0046);
    ak_rng zero = ak_rng_make(0);
    AK_CHECK(ak_rng_u32(&zero) != ak_rng_u32(&zero));
}

/* An independent UTF-8 oracle from the definition (RFC 3629): the lead byte gives the length,
 * continuation bytes are 10xxxxxx, the decoded code point must need that length (no overlong
 * form), must not be a surrogate, and must be at most U+10FFFF. */
static size_t oracle_utf8(const unsigned char* p, size_t avail) {
    if (!avail) return 0;
    size_t n = p[0] < 0x80 ? 1 : (p[0] & 0xE0) == 0xC0 ? 2 : (p[0] & 0xF0) == 0xE0 ? 3 : (p[0] & 0xF8) == 0xF0 ? 4 : 0;
    if (!n || n > avail) return 0;
    uint32_t cp = n == 1 ? p[0] : n == 2 ? p[0] & 0x1Fu : n == 3 ? p[0] & 0x0Fu : p[0] & 0x07u;
    for (size_t k = 1; k < n; ++k) {
        if ((p[k] & 0xC0) != 0x80) return 0;
        cp = (cp << 6) | (p[k] & 0x3Fu);
    }
    static const uint32_t min_for[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (n > 1 && cp < min_for[n]) return 0;
    if ((cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF) return 0;
    return n;
}

AK_TEST(utf8_char_matches_the_definition) {
    /* every lead byte with every second byte, and third/fourth bytes from the boundary values */
    static const unsigned char tail[] = {0x00, 0x3F, 0x7F, 0x80, 0x8F, 0x90, 0x9F, 0xA0, 0xBF, 0xC0, 0xFF};
    size_t bad = 0, checked = 0;
    for (int a = 0; a < 256; ++a)
        for (int b = 0; b < 256; ++b)
            for (size_t c = 0; c < sizeof tail; ++c)
                for (size_t d = 0; d < sizeof tail; ++d) {
                    const unsigned char s[4] = {(unsigned char)a, (unsigned char)b, tail[c], tail[d]};
                    for (size_t avail = 0; avail <= 4; ++avail) {
                        ++checked;
                        if (ak_utf8_char(s, avail) != oracle_utf8(s, avail)) ++bad;
                    }
                }
    AK_CHECK_MSG(bad == 0, "%zu of %zu sequences differ from the definition", bad, checked);
    AK_CHECK_EQ(ak_utf8_char(NULL, 4), 0u);
    AK_CHECK_EQ(ak_utf8_char("\xE2\x82\xAC", 3), 3u); /* the euro sign */
    AK_CHECK_EQ(ak_utf8_char("\xF4\x90\x80\x80", 4), 0u); /* U+110000 */
}

int main(void) {
    AK_RUN(result_strings_never_null);
    AK_RUN(rng_reproducible_and_uniform);
    AK_RUN(utf8_char_matches_the_definition);
    return ak_test_finish();
}
