//! The instruction set that lane code (and batches of ray queries) runs with, chosen at run
//! time: AVX2 where the CPU has it, else the baseline (SSE2 on x86-64, whatever the target has
//! elsewhere). Either can be asked for, so that tests and benchmarks compare them.

use super::LaneKernel;

/// An instruction set for lane code ([`Isa::run`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// 256-bit AVX2 (x86-64 CPUs that have it).
    Avx2,
    /// The target's baseline: each eight-lane operation as two SSE2 operations on x86-64.
    Portable,
}

impl Isa {
    /// Whether this CPU runs `self`.
    pub fn available(self) -> bool {
        match self {
            Isa::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            Isa::Avx2 => false,
        }
    }

    /// The best instruction set this CPU runs.
    pub fn best() -> Isa {
        if Isa::Avx2.available() { Isa::Avx2 } else { Isa::Portable }
    }

    /// The instruction set that the environment variable `TESSERA_SIMD` asks for (`avx2` or
    /// `portable`), or [`Isa::best`] where it is unset or empty. An error says what is wrong
    /// with the value: neither, or `avx2` on a CPU without it.
    pub fn from_env() -> Result<Isa, String> {
        match std::env::var("TESSERA_SIMD").as_deref() {
            Err(_) | Ok("") => Ok(Isa::best()),
            Ok("portable") => Ok(Isa::Portable),
            Ok("avx2") if Isa::Avx2.available() => Ok(Isa::Avx2),
            Ok("avx2") => Err("avx2 was asked for, but this CPU has no AVX2".into()),
            Ok(other) => Err(format!("{other:?} is not an instruction set: expected avx2 or portable")),
        }
    }

    /// [`Isa::from_env`], read once per process; [`Isa::best`] where that is an error (which
    /// the command line reports before it renders).
    pub fn selected() -> Isa {
        static SELECTED: std::sync::OnceLock<Isa> = std::sync::OnceLock::new();
        *SELECTED.get_or_init(|| Isa::from_env().unwrap_or_else(|_| Isa::best()))
    }

    /// `f()`, compiled for this instruction set: everything `f` inlines (lane operations are all
    /// `#[inline(always)]`) is compiled for AVX2 under [`Isa::Avx2`]. Portable where `self` is
    /// not [`Isa::available`]. A large `f` must itself be marked `#[inline(always)]` where it is
    /// written (`isa.run(#[inline(always)] || ...)`), and must not call helper closures: LLVM
    /// leaves a large closure out of line, compiled without AVX2 (`objdump -d` of `with_avx2`
    /// shows a jump to it).
    #[inline(always)]
    pub fn run<R>(self, f: impl FnOnce() -> R) -> R {
        #[cfg(target_arch = "x86_64")]
        if self == Isa::Avx2 && self.available() {
            #[target_feature(enable = "avx2")]
            #[allow(unsafe_code)]
            unsafe fn with_avx2<R>(f: impl FnOnce() -> R) -> R {
                f()
            }
            // SAFETY: the CPU has AVX2 (checked just above).
            #[allow(unsafe_code)]
            return unsafe { with_avx2(f) };
        }
        f()
    }

    /// `kernel`, with AVX2's operations ([`super::Avx2Lanes`], the kernel compiled for them)
    /// under [`Isa::Avx2`] where the CPU runs them, else the portable ones, which give the same
    /// bits.
    #[inline(always)]
    pub fn run_lanes<K: LaneKernel>(self, kernel: K) -> K::Output {
        #[cfg(target_arch = "x86_64")]
        if self == Isa::Avx2
            && let Some(lanes) = super::Avx2Lanes::new()
        {
            return lanes.0.vectorize(
                #[inline(always)]
                move || kernel.run(lanes),
            );
        }
        kernel.run(super::PortableLanes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_portable_set_is_always_available_and_run_calls_f() {
        assert!(Isa::Portable.available());
        for isa in [Isa::Avx2, Isa::Portable] {
            assert_eq!(isa.run(|| 41 + 1), 42);
        }
    }
}
