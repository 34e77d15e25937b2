//! Denormal (subnormal) floats flushed to zero while a render's samples are taken, as Embree asks of the
//! programs that call it ("for best performance set FTZ and DAZ flags in MXCSR").
//!
//! Why it pays: compiled code often does packed arithmetic on a vector whose other lanes hold whatever an
//! earlier instruction left there (a scalar `o.x − v0.x` as a four-lane `vsubps`, its upper lanes the halves of
//! a pointer: 3.06·10⁻⁴¹ as a float, seen under gdb with the denormal exception unmasked). Intel CPUs run such an
//! operation, or one that produces a denormal, through a microcode assist of a hundred cycles or more; on an
//! Intel Xeon (Emerald Rapids) a whole `render` of the Cornell box took 12% less time with the flags set
//! (docs/performance-history.md, seventeenth session). A value changes only where it is below 1.2·10⁻³⁸ in
//! magnitude (a Phong lobe's (ω·ω_r)^α underflowing at large α, say): it becomes 0.
//!
//! Every part of a render that must give the same bits as another runs under the same flags: both the one-sample
//! and the eight-lane path run inside [`without_denormals`] (see `render::pass`), so films stay identical with
//! any number of threads, passes or lanes; the census and the probe take their samples under the same flags.
//!
//! x86-64 only (the MXCSR's FTZ and DAZ bits); elsewhere the closure runs as it is.
#![allow(unsafe_code)]

/// MXCSR bit 15, flush to zero (FTZ): a result too small to be normal is 0.
#[cfg(target_arch = "x86_64")]
const FLUSH_TO_ZERO: u32 = 1 << 15;
/// MXCSR bit 6, denormals are zero (DAZ): an operand too small to be normal is read as 0.
#[cfg(target_arch = "x86_64")]
const DENORMALS_ARE_ZERO: u32 = 1 << 6;

/// Runs `f` with denormal results flushed to zero and denormal operands read as zero on this thread, then
/// restores the thread's earlier floating-point control (also if `f` panics).
pub fn without_denormals<R>(f: impl FnOnce() -> R) -> R {
    let _restore = Flags::set();
    call(f)
}

/// Calls `f`, never inlined: the compiler assumes the default floating-point environment and may move
/// arithmetic across the `ldmxcsr` that changes it (a sum inside `f` was computed before it, seen in an optimised
/// test build), but not out of a call it cannot see into, nor a call across the `asm!` blocks.
#[inline(never)]
fn call<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// The thread's MXCSR as it was before [`Flags::set`]; put back when dropped.
struct Flags {
    #[cfg(target_arch = "x86_64")]
    earlier: u32,
}

impl Flags {
    #[cfg(target_arch = "x86_64")]
    fn set() -> Self {
        let earlier = read_mxcsr();
        write_mxcsr(earlier | FLUSH_TO_ZERO | DENORMALS_ARE_ZERO);
        Self { earlier }
    }

    #[cfg(not(target_arch = "x86_64"))]
    fn set() -> Self {
        Self {}
    }
}

impl Drop for Flags {
    fn drop(&mut self) {
        #[cfg(target_arch = "x86_64")]
        write_mxcsr(self.earlier);
    }
}

#[cfg(target_arch = "x86_64")]
fn read_mxcsr() -> u32 {
    let mut mxcsr = 0u32;
    // SAFETY: `stmxcsr` stores the 4-byte MXCSR at the address given, a live, aligned u32 (x86-64 has SSE).
    unsafe { std::arch::asm!("stmxcsr [{}]", in(reg) &mut mxcsr, options(nostack, preserves_flags)) };
    mxcsr
}

/// Loads `mxcsr` into the MXCSR. Only the FTZ and DAZ bits differ from what the thread had: the rounding mode
/// and the exception masks stay as they are, so no instruction traps or rounds otherwise.
#[cfg(target_arch = "x86_64")]
fn write_mxcsr(mxcsr: u32) {
    // SAFETY: `ldmxcsr` loads the 4-byte MXCSR from a live, aligned u32; the value is the thread's own with at
    // most the FTZ and DAZ bits changed (no reserved bit set: that would fault).
    unsafe { std::arch::asm!("ldmxcsr [{}]", in(reg) &mxcsr, options(nostack, preserves_flags, readonly)) };
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    /// A denormal that the compiler cannot fold: it comes through `black_box`.
    fn tiny() -> f32 {
        std::hint::black_box(f32::MIN_POSITIVE / 4.0)
    }

    #[test]
    fn denormals_are_flushed_inside_and_kept_outside() {
        let before = read_mxcsr();
        assert!(tiny() * 1.0 > 0.0, "outside, a denormal operand is kept");
        let (product, operand_is_zero) = without_denormals(|| {
            let normal = std::hint::black_box(f32::MIN_POSITIVE);
            (normal * 0.25, tiny() + 0.0 == 0.0)
        });
        assert_eq!(product, 0.0, "a denormal result is flushed to zero");
        assert!(operand_is_zero, "a denormal operand is read as zero");
        assert_eq!(read_mxcsr() & !0x3f, before & !0x3f, "the control bits are restored (status flags aside)");
        assert!(tiny() * 1.0 > 0.0);
    }

    #[test]
    fn the_flags_are_restored_after_a_panic() {
        let before = read_mxcsr() & !0x3f;
        let caught = std::panic::catch_unwind(|| without_denormals(|| panic!("inside")));
        assert!(caught.is_err());
        assert_eq!(read_mxcsr() & !0x3f, before);
    }
}
