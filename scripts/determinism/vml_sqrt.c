/*
 * An LD_PRELOAD replacement for MKL's vmsSqrt (libtorch's Tensor::sqrt on the CPU) that computes
 * what MKL's kernel computes, with the rsqrtps estimate taken from a chosen source:
 *
 *   SEADS_RSQRT_TABLE unset   this processor's rsqrtps
 *   SEADS_RSQRT_TABLE=FILE    a table of 2 x 1024 estimates (text, one hexadecimal 16-bit entry
 *                             per line: even exponents first, then odd), indexed by the
 *                             input's 10 leading fraction bits
 *
 * MKL's kernel (mkl_vml_kernel_sSqrt_EXHAynn, the branch the portable kernels run), per lane, in
 * single precision without fused operations: y = rsqrtps(x); s = x*y; h = 0.5*y; r = 0.5 - s*h;
 * s1 = s + s*r; h1 = h + h*r; result = s1 + (x - s1*s1)*h1. Zero, subnormal, negative and
 * non-finite inputs take MKL's slow path, which returns the exact root (or NaN); so does this.
 *
 * Used by scripts/determinism/rsqrt_emulation.sh (see there). Not part of any build.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xmmintrin.h>

static uint16_t table[2][1024];
static int use_table = -1;

static void load_table(void) {
  const char *path = getenv("SEADS_RSQRT_TABLE");
  use_table = 0;
  if (path == NULL || *path == '\0') return;
  FILE *f = fopen(path, "r");
  if (f == NULL) { fprintf(stderr, "vml_sqrt: cannot open %s\n", path); exit(2); }
  for (int i = 0; i < 2048; i++) {
    unsigned v;
    if (fscanf(f, "%x", &v) != 1) { fprintf(stderr, "vml_sqrt: %s: short table\n", path); exit(2); }
    table[i / 1024][i % 1024] = (uint16_t)v;
  }
  fclose(f);
  use_table = 1;
}

static float bits_to_float(uint32_t b) { float f; memcpy(&f, &b, 4); return f; }

/* The estimate of 1/sqrt(x) for a positive normal x. */
static float estimate(float x, uint32_t bits) {
  if (!use_table) return _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));
  int exponent = (int)((bits >> 23) & 0xff);
  uint32_t entry = table[exponent & 1][(bits & 0x7fffff) >> 13];
  uint32_t result_exponent = (uint32_t)(126 - ((exponent - 127) >> 1));
  return bits_to_float((result_exponent << 23) | (entry << 8));
}

void vmsSqrt(int n, const float *a, float *r, long long mode) {
  (void)mode;
  if (use_table < 0) load_table();
  for (int i = 0; i < n; i++) {
    float x = a[i];
    uint32_t bits;
    memcpy(&bits, &x, 4);
    uint32_t exponent = (bits >> 23) & 0xff;
    if ((bits >> 31) != 0 || exponent == 0 || exponent == 0xff) {
      r[i] = sqrtf(x);
      continue;
    }
    float y = estimate(x, bits);
    float s = x * y, h = 0.5f * y;
    float t = 0.5f - s * h;
    float s1 = s + s * t, h1 = h + h * t;
    r[i] = s1 + (x - s1 * s1) * h1;
  }
}
