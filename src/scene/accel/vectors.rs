//! Which vector instructions the shadow rays' shared walk runs with, chosen once at run time: sixteen lanes
//! (`super::avx512`) where the CPU has AVX-512, eight (AVX2 and FMA, as the shipped x86-64-v3 build assumes)
//! elsewhere. Both give the same answers bit for bit; `ILLUMLAB_VECTORS=avx2` in the environment chooses the
//! eight lanes on any CPU, to compare the two in one binary.

use std::sync::OnceLock;

/// The vector instructions the shadow rays' shared walk runs with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VectorPath {
    /// Eight lanes: one box or one triangle against eight rays per test.
    Avx2,
    /// Sixteen lanes: two boxes or two triangles against eight rays per test.
    Avx512,
}

impl VectorPath {
    /// What the status bar, `render` and `bench` print.
    pub fn name(self) -> &'static str {
        match self {
            Self::Avx2 => "8 lanes (AVX2)",
            Self::Avx512 => "16 lanes (AVX-512)",
        }
    }

    /// Rays walk a subtree together while at least this many of them enter it; fewer go on alone, since a node
    /// costs the bundle its children's box tests whatever the number of rays still in it (Benthin et al.,
    /// "Combining Single and Packet-Ray Tracing for Arbitrary Ray Distributions on the Intel MIC Architecture",
    /// 2012). Sixteen lanes test two children per vector, so the shared walk pays off with fewer rays: measured
    /// on an Intel Xeon (AVX-512) with every room's leaves split (2026-12-05), 2 rather than 5 made the Cornell
    /// box's `emitter` about 6% faster and the knot's 3–10%; on the eight-lane path 5 was kept (3 and 7: within
    /// 0.2% and +3% instructions on an AMD EPYC, 2026-12-02; this Xeon's eight-lane timings did not decide).
    pub fn packet_min_rays(self) -> u32 {
        match self {
            Self::Avx2 => 5,
            Self::Avx512 => 2,
        }
    }
}

/// The path this process runs: AVX-512 where the CPU has it, unless `ILLUMLAB_VECTORS=avx2`. Decided once.
pub fn vector_path() -> VectorPath {
    static PATH: OnceLock<VectorPath> = OnceLock::new();
    *PATH.get_or_init(|| {
        let forced = std::env::var("ILLUMLAB_VECTORS").is_ok_and(|v| v.eq_ignore_ascii_case("avx2"));
        if !forced && has_avx512() { VectorPath::Avx512 } else { VectorPath::Avx2 }
    })
}

/// Whether the CPU has the AVX-512 subsets (F, DQ, VL, BW) the 16-lane code is compiled for, and this build
/// has that code (x86-64 with FMA: its fused operations are the eight-lane code's).
pub fn has_avx512() -> bool {
    static HAS: OnceLock<bool> = OnceLock::new();
    *HAS.get_or_init(|| {
        #[cfg(all(target_arch = "x86_64", target_feature = "fma"))]
        {
            is_x86_feature_detected!("avx512f")
                && is_x86_feature_detected!("avx512dq")
                && is_x86_feature_detected!("avx512vl")
                && is_x86_feature_detected!("avx512bw")
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "fma")))]
        false
    })
}
