//! The SIMD width of the hot kernels, chosen once per process at run time.
//!
//! The build targets `x86-64-v2` (SSE4.2), so that one binary runs on any x86-64 CPU since
//! 2009. Three kernels also exist compiled for wider vectors and are chosen at run time from
//! what the CPU has ([`level`]):
//!
//! - the BVH traversal ([`crate::accel::Kernel`]): a node's 8 child boxes in one AVX2 pass
//!   (two in SSE), or, where the CPU has AVX-512, 16 children in one pass (the BVH is then
//!   built 16 wide);
//! - the light choice's weights of a tree node's children and the BSDF toward them
//!   ([`crate::light`]'s node lanes): 4 children at a time in SSE, 8 in AVX2, all 16 in one
//!   AVX-512 pass.
//!
//! Every kernel does the same IEEE operations in each lane at every width, in the same order,
//! and none uses fused multiply-adds (an FMA rounds once where a multiply and an add round
//! twice, so it would change the bits with the CPU): the images are bit for bit the same on
//! every CPU a binary runs on (tested by running each width this CPU has on the same
//! inputs). `STREAKS_SIMD=sse|avx2|avx512` caps the width, for measurements and to check
//! that claim; a width the CPU lacks is never used.

use std::sync::OnceLock;

/// The widest SIMD the hot kernels use in this process.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum SimdLevel {
    /// 128-bit SSE (the build's baseline): 4 lanes of `f32`.
    Sse,
    /// 256-bit AVX2: 8 lanes.
    Avx2,
    /// 512-bit AVX-512 (AVX-512F): 16 lanes.
    Avx512,
}

impl SimdLevel {
    /// The widest level this CPU runs (SSE on other architectures, where the SSE kernels are
    /// plain portable code).
    pub fn of_cpu() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                return Self::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                return Self::Avx2;
            }
        }
        Self::Sse
    }

    /// The level named by `STREAKS_SIMD` (`sse`, `avx2` or `avx512`, any case); `None` when
    /// unset or not one of these.
    pub fn requested(value: Option<&str>) -> Option<Self> {
        match value?.to_ascii_lowercase().as_str() {
            "sse" => Some(Self::Sse),
            "avx2" => Some(Self::Avx2),
            "avx512" => Some(Self::Avx512),
            _ => None,
        }
    }

    /// The level used: the CPU's, capped by `requested` when given.
    pub fn choose(cpu: Self, requested: Option<Self>) -> Self {
        requested.map_or(cpu, |r| r.min(cpu))
    }

    /// Its name, as `STREAKS_SIMD` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sse => "sse",
            Self::Avx2 => "avx2",
            Self::Avx512 => "avx512",
        }
    }
}

/// The SIMD level of this process: the CPU's widest, capped by `STREAKS_SIMD` (read once).
pub fn level() -> SimdLevel {
    static LEVEL: OnceLock<SimdLevel> = OnceLock::new();
    *LEVEL.get_or_init(|| {
        let requested = std::env::var("STREAKS_SIMD").ok();
        SimdLevel::choose(
            SimdLevel::of_cpu(),
            SimdLevel::requested(requested.as_deref()),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_caps_the_cpu_level_and_never_raises_it() {
        use SimdLevel::*;
        assert_eq!(SimdLevel::requested(Some("AVX2")), Some(Avx2));
        assert_eq!(SimdLevel::requested(Some("avx512")), Some(Avx512));
        assert_eq!(SimdLevel::requested(Some("neon")), None);
        assert_eq!(SimdLevel::requested(None), None);
        assert_eq!(SimdLevel::choose(Avx512, Some(Sse)), Sse);
        assert_eq!(SimdLevel::choose(Avx2, Some(Avx512)), Avx2);
        assert_eq!(SimdLevel::choose(Avx2, None), Avx2);
        assert!(level() <= SimdLevel::of_cpu());
    }
}
