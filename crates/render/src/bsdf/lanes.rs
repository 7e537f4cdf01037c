//! The number types every lobe is written in, so that one function serves both evaluations of
//! a model: [`Lanes`], one direction's scalar (`f32`) or four directions' in SIMD lanes
//! (`Vec4`), and [`Spectrum`], what a reflectance is while a lobe is evaluated: linear RGB
//! (`Vec3`, with `f32` lanes) for `eval`, `pdf` and `sample`, or its luminance in lanes for
//! [`super::LuminanceEval`].
//!
//! Every operation is the IEEE one in each lane, so a lane holds exactly the scalar result.

use glam::{Vec3, Vec4};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A number, or four of them in SIMD lanes: the lobes are written once for both, and the light
/// choice evaluates four emitters at a time.
pub(crate) trait Lanes:
    Copy
    + Add<Output = Self>
    + Add<f32, Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Mul<f32, Output = Self>
    + Div<Output = Self>
    + Div<f32, Output = Self>
    + Neg<Output = Self>
{
    /// The same value in every lane.
    fn splat(x: f32) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `e^self`.
    fn exp(self) -> Self;
    /// `self^e`.
    fn powf(self, e: f32) -> Self;
    /// `self^5`, as `f32::powi(self, 5)` computes it.
    fn pow5(self) -> Self;
    /// Clamped to `[0, 1]`.
    fn saturate(self) -> Self;
    /// `self` where `z > 0`, else 0.
    fn where_positive(self, z: Self) -> Self;
}

impl Lanes for f32 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f32::exp(self)
    }
    #[inline(always)]
    fn powf(self, e: f32) -> Self {
        f32::powf(self, e)
    }
    #[inline(always)]
    fn pow5(self) -> Self {
        self.powi(5)
    }
    #[inline(always)]
    fn saturate(self) -> Self {
        self.clamp(0.0, 1.0)
    }
    #[inline(always)]
    fn where_positive(self, z: Self) -> Self {
        if z > 0.0 {
            self
        } else {
            0.0
        }
    }
}

impl Lanes for Vec4 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Vec4::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vec4::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Vec4::abs(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        Vec4::from_array(self.to_array().map(f32::exp))
    }
    #[inline(always)]
    fn powf(self, e: f32) -> Self {
        Vec4::from_array(self.to_array().map(|x| x.powf(e)))
    }
    #[inline(always)]
    fn pow5(self) -> Self {
        Vec4::from_array(self.to_array().map(|x| x.powi(5)))
    }
    #[inline(always)]
    fn saturate(self) -> Self {
        self.clamp(Vec4::ZERO, Vec4::ONE)
    }
    #[inline(always)]
    fn where_positive(self, z: Self) -> Self {
        Vec4::select(z.cmpgt(Vec4::ZERO), self, Vec4::ZERO)
    }
}

/// A reflectance while a lobe is evaluated in lanes `L`: linear RGB (`Vec3`, for `L = f32`), or
/// its luminance (`L` itself). A lobe only adds reflectances and greys, scales them by lane
/// terms and takes `1 -` them, so evaluated on luminances it gives the luminance of its RGB
/// value (luminance is linear, and `1 - luminance(c) = luminance(1 - c)` and
/// `luminance(grey(x)) = x` as the weights sum to 1).
pub(crate) trait Spectrum<L: Lanes>:
    Copy + Add<Output = Self> + Mul<L, Output = Self> + Mul<f32, Output = Self>
{
    /// `1 - self`, per channel.
    fn one_minus(self) -> Self;
    /// The grey reflectance `x` in every channel (whose luminance is `x`).
    fn grey(x: L) -> Self;
}

impl Spectrum<f32> for Vec3 {
    #[inline(always)]
    fn one_minus(self) -> Self {
        Vec3::ONE - self
    }
    #[inline(always)]
    fn grey(x: f32) -> Self {
        Vec3::splat(x)
    }
}

impl<L: Lanes> Spectrum<L> for L {
    #[inline(always)]
    fn one_minus(self) -> Self {
        L::splat(1.0) - self
    }
    #[inline(always)]
    fn grey(x: L) -> Self {
        x
    }
}
