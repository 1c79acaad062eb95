/* The C library's calls that one free-link evaluation makes (one sin/cos pair and one pow),
 * at full throughput: glibc's scalar sincos and pow, which granrs and the numba peers call,
 * against glibc's 4-lane AVX2 vector versions (libmvec: _ZGVdN4v_sin, _ZGVdN4v_cos,
 * _ZGVdN4vv_pow), which the SIMD lanes could call if their results were allowed to differ
 * from the scalar path's. Prints ns per evaluation's calls for both, and how far the vector
 * results are from the scalar ones (libmvec documents up to 4 ulp). docs/sweeps.md ("What
 * the speed targets leave") quotes these numbers beside benches/peers.py's.
 *
 * x86-64 with AVX2 and glibc >= 2.22 only:
 *
 *     gcc -O2 -mavx2 -mfma benches/libm_vector.c -o /tmp/libm_vector -lmvec -lm
 *     /tmp/libm_vector
 */
#define _GNU_SOURCE
#include <immintrin.h>
#include <math.h>
#include <stdio.h>
#include <time.h>

__m256d _ZGVdN4v_sin(__m256d);
__m256d _ZGVdN4v_cos(__m256d);
__m256d _ZGVdN4vv_pow(__m256d, __m256d);

/* Evaluations per pass: angles and depths of an impact (q in 0..85 deg, depth 0..5 cm). */
#define N 4096
static double q[N], depth[N], out_v[N], out_s[N];

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* No call waits for another: the calls' throughput cost. */
__attribute__((noinline)) static void vector(double lam) {
    __m256d l = _mm256_set1_pd(lam);
    for (int i = 0; i < N; i += 4) {
        __m256d x = _mm256_loadu_pd(q + i), d = _mm256_loadu_pd(depth + i);
        __m256d r = _mm256_add_pd(_mm256_mul_pd(_ZGVdN4v_sin(x), _ZGVdN4v_cos(x)),
                                  _ZGVdN4vv_pow(d, l));
        _mm256_storeu_pd(out_v + i, r);
    }
}

__attribute__((noinline)) static void scalar(double lam) {
    for (int i = 0; i < N; i++) {
        double s, c;
        sincos(q[i], &s, &c);
        out_s[i] = s * c + pow(depth[i], lam);
    }
}

int main(void) {
    for (int i = 0; i < N; i++) {
        q[i] = 1.48 * i / N;
        depth[i] = 1e-4 + 0.05 * i / N;
    }
    double best_v = 1.0, best_s = 1.0;
    for (int r = 0; r < 2000; r++) {
        double t = now();
        vector(0.25);
        t = now() - t;
        best_v = t < best_v ? t : best_v;
        t = now();
        scalar(0.25);
        t = now() - t;
        best_s = t < best_s ? t : best_s;
    }
    double worst = 0.0;
    for (int i = 0; i < N; i++) {
        double rel = fabs(out_v[i] - out_s[i]) / fabs(out_s[i]);
        worst = rel > worst ? rel : worst;
    }
    printf("scalar glibc (sincos, pow): %.2f ns per evaluation's calls\n", best_s * 1e9 / N);
    printf("vector libmvec (sin, cos, pow; 4 lanes): %.2f ns per evaluation's calls\n",
           best_v * 1e9 / N);
    printf("vector / scalar: %.2f; largest relative difference of the results: %.1e\n",
           best_v / best_s, worst);
    return 0;
}
