//! The C library's four-lane calls for the lanes' `sin_cos` and `pow`: glibc's AVX2 vector
//! math (libmvec: `_ZGVdN4v_sin`, `_ZGVdN4v_cos`, `_ZGVdN4vv_pow`), found at run time.
//!
//! Why: one free-link evaluation makes one `sin`/`cos` pair and one `pow`. Called lane by
//! lane they take 21-23 ns per scene evaluation at full throughput, glibc's four-lane
//! versions 6.8 ns (`benches/libm_vector.c`). A `sin_cos` and a `pow` of granrs's own, shared
//! by the scalar path and the lanes so that both give the same bits, were written and
//! measured: the lanes gained 8 %, `simulate` lost 22 %, and the `pow` took four times libm's
//! time.
//!
//! Opt-in, not the default: glibc documents at most 4 ulp per call, and a last bit can tip a
//! decision of the run (a stick-slip sign grazing zero, a stop located on a flat
//! interpolant). Measured over 500 random free-link scenes per law
//! (`benches/lanes_agreement.py`): under the thesis's law with held signs every row within
//! 1e-12 relative of the scalar path; under `rft`, `poncelet` and `smooth` 3-4 % of rows
//! beyond it, up to 1e-9 where no decision tipped and up to 3e-2 where one did (runs that
//! warn). A sweep's row is `simulate`'s bit for bit by default; `GRANRS_FAST_LANES=1`
//! trades that for the speed (docs/sweeps.md, "The lanes and the scalar path").
//!
//! The library is opened with `dlopen`, not linked: a wheel built against a glibc without
//! libmvec (before 2.22), or run where it is missing, loads and runs lane by lane. The calls
//! are taken only where the CPU has AVX2 (the `d` variants need it) and the environment
//! variable `GRANRS_FAST_LANES` is `1` (read once per process).

/// Whether the lanes call glibc's four-lane `sin`, `cos` and `pow` (`GRANRS_FAST_LANES=1`,
/// AVX2, libmvec found).
#[inline(always)]
pub fn active() -> bool {
    imp::calls().is_some()
}

/// `sin` and `cos` of four lanes, or `None` where the vector calls are not active.
#[inline(always)]
pub fn sin_cos(x: [f64; 4]) -> Option<([f64; 4], [f64; 4])> {
    imp::calls().map(|c| c.sin_cos(x))
}

/// `x^e` in four lanes, or `None` where the vector calls are not active.
#[inline(always)]
pub fn pow(x: [f64; 4], e: [f64; 4]) -> Option<[f64; 4]> {
    imp::calls().map(|c| c.pow(x, e))
}

#[cfg(all(target_arch = "x86_64", target_os = "linux", target_env = "gnu"))]
mod imp {
    use std::arch::x86_64::{__m256d, _mm256_loadu_pd, _mm256_storeu_pd};
    use std::ffi::CStr;
    use std::sync::OnceLock;

    // `__m256d` crosses the C ABI in a ymm register (the x86-64 vector ABI libmvec's `d`
    // variants use); the calls are made only from `avx2` functions below.
    #[allow(improper_ctypes_definitions)]
    type Unary = unsafe extern "C" fn(__m256d) -> __m256d;
    #[allow(improper_ctypes_definitions)]
    type Binary = unsafe extern "C" fn(__m256d, __m256d) -> __m256d;

    /// The three entry points, resolved once.
    #[derive(Clone, Copy)]
    pub struct Calls {
        sin: Unary,
        cos: Unary,
        pow: Binary,
    }

    static CALLS: OnceLock<Option<Calls>> = OnceLock::new();

    #[inline(always)]
    pub fn calls() -> Option<&'static Calls> {
        CALLS.get_or_init(load).as_ref()
    }

    fn load() -> Option<Calls> {
        if !std::env::var("GRANRS_FAST_LANES").is_ok_and(|v| v.trim() == "1") {
            return None;
        }
        resolve()
    }

    /// The three calls where the CPU has AVX2 and libmvec is found, whatever the switch.
    pub fn resolve() -> Option<Calls> {
        if !crate::num::avx2() {
            return None;
        }
        let lib: &CStr = c"libmvec.so.1";
        // SAFETY: dlopen and dlsym with NUL-terminated names; the handle is kept for the
        // process's life (never closed), so the symbols stay valid.
        unsafe {
            let handle = libc::dlopen(lib.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL);
            if handle.is_null() {
                return None;
            }
            let sym = |name: &CStr| {
                let p = libc::dlsym(handle, name.as_ptr());
                (!p.is_null()).then_some(p)
            };
            let (sin, cos, pow) = (
                sym(c"_ZGVdN4v_sin")?,
                sym(c"_ZGVdN4v_cos")?,
                sym(c"_ZGVdN4vv_pow")?,
            );
            Some(Calls {
                sin: std::mem::transmute::<*mut libc::c_void, Unary>(sin),
                cos: std::mem::transmute::<*mut libc::c_void, Unary>(cos),
                pow: std::mem::transmute::<*mut libc::c_void, Binary>(pow),
            })
        }
    }

    impl Calls {
        #[inline(always)]
        pub fn sin_cos(&self, x: [f64; 4]) -> ([f64; 4], [f64; 4]) {
            // SAFETY: `Calls` exist only where the CPU has AVX2 (`load`).
            unsafe { sin_cos_avx2(self, x) }
        }

        #[inline(always)]
        pub fn pow(&self, x: [f64; 4], e: [f64; 4]) -> [f64; 4] {
            // SAFETY: as above.
            unsafe { pow_avx2(self, x, e) }
        }
    }

    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn sin_cos_avx2(c: &Calls, x: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        let (mut s, mut co) = ([0.0; 4], [0.0; 4]);
        let v = _mm256_loadu_pd(x.as_ptr());
        _mm256_storeu_pd(s.as_mut_ptr(), (c.sin)(v));
        _mm256_storeu_pd(co.as_mut_ptr(), (c.cos)(v));
        (s, co)
    }

    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn pow_avx2(c: &Calls, x: [f64; 4], e: [f64; 4]) -> [f64; 4] {
        let mut out = [0.0; 4];
        let r = (c.pow)(_mm256_loadu_pd(x.as_ptr()), _mm256_loadu_pd(e.as_ptr()));
        _mm256_storeu_pd(out.as_mut_ptr(), r);
        out
    }
}

#[cfg(not(all(target_arch = "x86_64", target_os = "linux", target_env = "gnu")))]
mod imp {
    /// No vector calls on this platform: the lanes call libm lane by lane.
    pub struct Calls;

    impl Calls {
        pub fn sin_cos(&self, _: [f64; 4]) -> ([f64; 4], [f64; 4]) {
            unreachable!()
        }
        pub fn pow(&self, _: [f64; 4], _: [f64; 4]) -> [f64; 4] {
            unreachable!()
        }
    }

    #[inline(always)]
    pub fn calls() -> Option<&'static Calls> {
        None
    }

    #[cfg(test)]
    pub fn resolve() -> Option<Calls> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where the vector calls can be found, each lane is within 4 ulp of libm's scalar call
    /// (glibc's documented bound) on the angles and depth ratios the free link meets, and
    /// special values keep their meaning.
    #[test]
    fn vector_calls_are_within_four_ulp_of_libm() {
        // Resolved here whatever the switch (the test runs where the calls can be found).
        let Some(c) = imp::resolve() else {
            return;
        };
        let sin_cos = |x| Some(c.sin_cos(x));
        let pow = |x, e| Some(c.pow(x, e));
        let ulp = |a: f64, b: f64| ((a.to_bits() as i64) - (b.to_bits() as i64)).abs();
        let mut worst = [0i64; 3];
        for i in 0..20_000 {
            let t = i as f64 / 20_000.0;
            let x = [
                -3.2 + 6.4 * t,
                1e-9 + t,
                40.0 * t - 20.0,
                std::f64::consts::FRAC_PI_2 * t,
            ];
            let (s, c) = sin_cos(x).unwrap();
            let base = [1e-6 + t, 0.26 * t + 1e-3, 0.5 + t, 2.0 * t + 1e-12];
            let e = [0.106, 0.5, 1.0, 1.7 * t];
            let p = pow(base, e).unwrap();
            for k in 0..4 {
                let (s0, c0) = x[k].sin_cos();
                worst[0] = worst[0].max(ulp(s[k], s0));
                worst[1] = worst[1].max(ulp(c[k], c0));
                worst[2] = worst[2].max(ulp(p[k], base[k].powf(e[k])));
            }
        }
        assert!(worst.iter().all(|&w| w <= 4), "ulp distances {worst:?}");
        let p = pow([0.0, 1.0, 2.0, 0.0], [0.106, 0.0, 1.0, 1.0]).unwrap();
        assert_eq!(p, [0.0, 1.0, 2.0, 0.0]);
    }
}
