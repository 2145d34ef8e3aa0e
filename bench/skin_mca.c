/* Regions for bench/skin_mca.sh: one block (8 vertices, 4 influences, tightly packed positions
 * and normals) of each AVX2 skinning kernel, as the block loops in src/skin/deform_avx2.c run
 * it, between LLVM-MCA markers. Compiled to assembly only (never linked or run): llvm-mca
 * models the instruction stream on a given CPU's pipes. The strides are constants here, so
 * the stride-12 shuffles are the only path the compiler keeps. */
#include "skin/deform_avx2.c"

#if AKP_HAVE_AVX2_KERNEL
/* stands for the 3x4-row palette copy that block_lbs_range makes (palettes <= 256 joints) */
static _Alignas(64) float mca_rows3[AKP_ROWS3_MAX * 16];

#define MCA_CTX(normals)                                                                           \
    akp_skin_ctx c = *cin;                                                                         \
    c.pos_stride = c.nrm_stride = c.out_pos_stride = c.out_nrm_stride = c.ctr_stride = 12;         \
    c.jnt_stride = 8;                                                                              \
    c.wgt_stride = 16;                                                                             \
    c.k = 4;                                                                                       \
    c.do_normals = (normals)

#define MCA_LBS(name, normals)                                                                     \
    AKP_AVX2 void mca_##name(const akp_skin_ctx* cin, size_t begin, size_t end) {                  \
        MCA_CTX(normals);                                                                          \
        uint32_t off[2][32];                                                                       \
        unsigned b = 0;                                                                            \
        for (size_t i = begin; i < end; i += 8, b ^= 1u) {                                         \
            __asm volatile("# LLVM-MCA-BEGIN " #name);                                             \
            offsets8_dense(&c, i + 8, off[b ^ 1u], 4); /* packed: the block loop's dense path */   \
            block_lbs(&c, i, 4, off[b], true, mca_rows3, (normals) ? AKP_IO_PN : AKP_IO_P);        \
            __asm volatile("# LLVM-MCA-END " #name);                                               \
        }                                                                                          \
    }

#define MCA_DQ(name, block, neg)                                                                   \
    AKP_AVX2 void mca_##name(const akp_skin_ctx* cin, size_t begin, size_t end) {                  \
        MCA_CTX(true);                                                                             \
        dq_prep p[3];                                                                              \
        unsigned b = 0;                                                                            \
        for (size_t i = begin; i < end; i += 8, b = b == 2u ? 0u : b + 1u) {                       \
            const unsigned b1 = b == 2u ? 0u : b + 1u, b2 = b1 == 2u ? 0u : b1 + 1u;               \
            __asm volatile("# LLVM-MCA-BEGIN " #name);                                             \
            joint_offsets(&c, i + 16, AKP_JOINT_SHIFT, p[b2].off, 4);                              \
            dq_signs_block(&c, i + 8, &p[b1], (neg), 4);                                           \
            block(&c, i, 4, &p[b]);                                                                \
            __asm volatile("# LLVM-MCA-END " #name);                                               \
        }                                                                                          \
    }

MCA_LBS(lbs_positions, false)
MCA_LBS(lbs_normals, true)
MCA_DQ(dqs_normals, block_dqs, 0u)
MCA_DQ(cor_normals, block_cor, 4096u)
#endif
