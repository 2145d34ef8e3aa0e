/* core: result strings, rng determinism and range. */
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

int main(void) {
    AK_RUN(result_strings_never_null);
    AK_RUN(rng_reproducible_and_uniform);
    return ak_test_finish();
}
