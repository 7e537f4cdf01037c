//! The number types every lobe is written in, so that one function serves both evaluations of
//! a model: [`Lanes`], one direction's scalar (`f32`) or several directions' in SIMD lanes
//! (`Vec4`: four in SSE; [`Wide`]: 8 or 16, which the compiler maps onto AVX2 or AVX-512
//! registers inside the kernels [`crate::simd`] chooses), and [`Spectrum`], what a
//! reflectance is while a lobe is evaluated: linear RGB (`Vec3`, with `f32` lanes) for `eval`,
//! `pdf` and `sample`, or its luminance in lanes for [`super::LuminanceEval`]. [`WideLanes`]
//! adds what the light choice's kernel needs besides the lobes: loads, stores, comparisons and
//! selects.
//!
//! Every operation is the IEEE one in each lane, so a lane holds exactly the scalar result,
//! at every width: no operation is fused (no FMA), and `max`/`min` are SSE's `maxps`/`minps`
//! (`a > b ? a : b`) at every width.

// `Wide`'s lane loops index their arrays on purpose: written with by-value array iterators
// (`zip(o.0)`), they were not turned into vector instructions.
#![allow(clippy::needless_range_loop)]

use glam::{BVec4A, Vec3, Vec4};
use std::ops::{Add, BitAnd, Div, Mul, Neg, Sub};

/// A number, or several of them in SIMD lanes: the lobes are written once for all, and the
/// light choice evaluates 4, 8 or 16 emitters at a time.
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
    /// `f` of each lane (a table lookup, say), one lane at a time.
    fn lanewise(self, f: impl Fn(f32) -> f32) -> Self;
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
    #[inline(always)]
    fn lanewise(self, f: impl Fn(f32) -> f32) -> Self {
        f(self)
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
    #[inline(always)]
    fn lanewise(self, f: impl Fn(f32) -> f32) -> Self {
        Vec4::from_array(self.to_array().map(f))
    }
}

/// `N` numbers in lanes, for the kernels compiled for AVX2 (`N = 8`) and AVX-512 (`N = 16`):
/// every operation is a loop over the lanes that the compiler turns into one vector
/// instruction inside a `#[target_feature]` kernel (and into scalar or SSE code anywhere
/// else, with the same results).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct Wide<const N: usize>(pub [f32; N]);

impl<const N: usize> Wide<N> {
    /// `op` lane by lane.
    #[inline(always)]
    fn map(self, op: impl Fn(f32) -> f32) -> Self {
        let mut out = self.0;
        for x in &mut out {
            *x = op(*x);
        }
        Wide(out)
    }

    /// The mask of `op` lane by lane on two operands.
    #[inline(always)]
    fn compare(self, o: Self, op: impl Fn(f32, f32) -> bool) -> WideMask<N> {
        let mut out = [0u32; N];
        for i in 0..N {
            out[i] = if op(self.0[i], o.0[i]) { u32::MAX } else { 0 };
        }
        WideMask(out)
    }

    /// `op` lane by lane on two operands.
    #[inline(always)]
    fn zip(self, o: Self, op: impl Fn(f32, f32) -> f32) -> Self {
        let mut out = self.0;
        for i in 0..N {
            out[i] = op(out[i], o.0[i]);
        }
        Wide(out)
    }
}

macro_rules! wide_binary_ops {
    ($($trait:ident $method:ident $op:tt),*) => {$(
        impl<const N: usize> $trait for Wide<N> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl<const N: usize> $trait<f32> for Wide<N> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: f32) -> Self {
                self.map(|a| a $op o)
            }
        }
    )*};
}
wide_binary_ops!(Add add +, Sub sub -, Mul mul *, Div div /);

impl<const N: usize> Neg for Wide<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(|a| -a)
    }
}

impl<const N: usize> Lanes for Wide<N> {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Wide([x; N])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f32::abs)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        Wide(exp_lanes(self.0))
    }
    #[inline(always)]
    fn powf(self, e: f32) -> Self {
        Wide(powf_lanes(self.0, e))
    }
    #[inline(always)]
    fn pow5(self) -> Self {
        self.map(|x| x.powi(5))
    }
    #[inline(always)]
    fn saturate(self) -> Self {
        // Vec4::clamp's order: max with 0 (maxps), then min with 1 (minps).
        self.map(|x| sse_min(sse_max(x, 0.0), 1.0))
    }
    #[inline(always)]
    fn where_positive(self, z: Self) -> Self {
        self.zip(z, |x, z| if z > 0.0 { x } else { 0.0 })
    }
    #[inline(always)]
    fn lanewise(self, f: impl Fn(f32) -> f32) -> Self {
        self.map(f)
    }
}

/// `e^x` lane by lane, by the C library one at a time. Never inlined, on purpose: inlined,
/// the compiler may compute it in every lane of a kernel before knowing that the model needs
/// it (LLVM treats `exp` as free of side effects and hoists it out of the model's `match`),
/// which in the AVX-512 kernel cost 16 `expf` calls per light-choice node for GGX roads.
#[inline(never)]
fn exp_lanes<const N: usize>(mut x: [f32; N]) -> [f32; N] {
    for v in &mut x {
        *v = v.exp();
    }
    x
}

/// `x^e` lane by lane, by the C library one at a time; never inlined, as [`exp_lanes`].
#[inline(never)]
fn powf_lanes<const N: usize>(mut x: [f32; N], e: f32) -> [f32; N] {
    for v in &mut x {
        *v = v.powf(e);
    }
    x
}

/// SSE's `maxps` on one lane: `a` if `a > b`, else `b` (so `b` when either is NaN).
#[inline(always)]
fn sse_max(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// SSE's `minps` on one lane: `a` if `a < b`, else `b`.
#[inline(always)]
fn sse_min(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// [`Lanes`] of a fixed width with what a kernel over arrays needs: loads and stores,
/// comparisons into masks, selects and `max`. Implemented for `Vec4` (SSE) and [`Wide`].
pub(crate) trait WideLanes: Lanes {
    /// Lanes per value.
    const WIDTH: usize;
    /// A lane mask (the result of a comparison).
    type Mask: Copy + BitAnd<Output = Self::Mask>;
    /// The first [`WideLanes::WIDTH`] values of `s`.
    fn load(s: &[f32]) -> Self;
    /// Writes the lanes to the first [`WideLanes::WIDTH`] values of `s`.
    fn store(self, s: &mut [f32]);
    /// Lanes where `self > o`.
    fn gt(self, o: Self) -> Self::Mask;
    /// Lanes where `self >= o`.
    fn ge(self, o: Self) -> Self::Mask;
    /// Lanes that are positive and finite (`0 < x < inf`; not NaN).
    fn positive_finite(self) -> Self::Mask;
    /// `a` where `m`, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// SSE's `maxps`, lane by lane: `self` where `self > o`, else `o`.
    fn max(self, o: Self) -> Self;
    /// Whether any lane of `m` is set.
    fn any(m: Self::Mask) -> bool;
}

impl WideLanes for Vec4 {
    const WIDTH: usize = 4;
    type Mask = BVec4A;
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        Vec4::from_slice(s)
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        self.write_to_slice(s)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> BVec4A {
        self.cmpgt(o)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> BVec4A {
        self.cmpge(o)
    }
    #[inline(always)]
    fn positive_finite(self) -> BVec4A {
        self.cmpgt(Vec4::ZERO) & self.cmplt(Vec4::INFINITY)
    }
    #[inline(always)]
    fn select(m: BVec4A, a: Self, b: Self) -> Self {
        Vec4::select(m, a, b)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Vec4::max(self, o)
    }
    #[inline(always)]
    fn any(m: BVec4A) -> bool {
        m.any()
    }
}

/// A mask of `N` lanes: all bits set where true, as SSE's and AVX's comparisons give (a
/// `bool` per lane would be a byte, which the compiler does not keep in vector registers).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(64))]
pub(crate) struct WideMask<const N: usize>([u32; N]);

impl<const N: usize> BitAnd for WideMask<N> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        let mut out = self.0;
        for i in 0..N {
            out[i] &= o.0[i];
        }
        WideMask(out)
    }
}

impl<const N: usize> WideLanes for Wide<N> {
    const WIDTH: usize = N;
    type Mask = WideMask<N>;
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        let mut out = [0.0; N];
        out.copy_from_slice(&s[..N]);
        Wide(out)
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        s[..N].copy_from_slice(&self.0)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> WideMask<N> {
        self.compare(o, |a, b| a > b)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> WideMask<N> {
        self.compare(o, |a, b| a >= b)
    }
    #[inline(always)]
    fn positive_finite(self) -> WideMask<N> {
        // The positive finite floats are the bit patterns 1 ..= 0x7f7f_ffff: one unsigned
        // comparison (as two float comparisons, the compiler turns it into a per-lane class
        // test that it does not vectorise).
        let mut out = [0u32; N];
        for i in 0..N {
            out[i] = if self.0[i].to_bits().wrapping_sub(1) < 0x7f7f_ffff {
                u32::MAX
            } else {
                0
            };
        }
        WideMask(out)
    }
    #[inline(always)]
    fn select(m: WideMask<N>, a: Self, b: Self) -> Self {
        let mut out = b.0;
        for i in 0..N {
            out[i] = f32::from_bits((a.0[i].to_bits() & m.0[i]) | (out[i].to_bits() & !m.0[i]));
        }
        Wide(out)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        self.zip(o, sse_max)
    }
    #[inline(always)]
    fn any(m: WideMask<N>) -> bool {
        m.0.iter().fold(0, |a, &b| a | b) != 0
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
    /// The reflectance `f(x)` of each lane's `x`, `f` giving linear RGB (its luminance for
    /// luminance lanes), one lane at a time.
    fn from_rgb(x: L, f: impl Fn(f32) -> Vec3) -> Self;
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
    #[inline(always)]
    fn from_rgb(x: f32, f: impl Fn(f32) -> Vec3) -> Self {
        f(x)
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
    #[inline(always)]
    fn from_rgb(x: L, f: impl Fn(f32) -> Vec3) -> Self {
        x.lanewise(|c| streaks_image::luminance(f(c)))
    }
}
