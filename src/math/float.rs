//! [`F32`]: `f32` arithmetic that rounds like binary32 hardware on every target, from integer
//! code (`math::soft`) where there is no FPU.

#[cfg(soft_float)]
use super::soft;
use super::to_i32;

/// An `f32` whose arithmetic (`+ - * /`, comparisons, `From<i32>`, `From<u32>`) rounds like
/// IEEE-754 binary32 hardware on every target: the FPU's instructions where there is one, and
/// integer code (`math::soft`) without, where the soft-float library's calls cost 2 to 5 times as
/// much (its multiply widens to a 64-bit library multiply, its conversions call `__clzsi2`).
/// The same bits either way, so frames stay bit-identical to the host's.
///
/// For the per-vertex, per-triangle and per-row float code; elsewhere plain `f32` is fine.
#[derive(Clone, Copy, Debug, Default)]
#[repr(transparent)]
pub struct F32(pub f32);

/// One binary operator of [`F32`]: `soft::$soft` without an FPU, the `f32` operator with one.
macro_rules! f32_operator {
    ($trait:ident, $method:ident, $soft:ident, $op:tt) => {
        impl core::ops::$trait for F32 {
            type Output = F32;
            #[inline(always)]
            fn $method(self, other: F32) -> F32 {
                #[cfg(soft_float)]
                {
                    F32(soft::$soft(self.0, other.0))
                }
                #[cfg(not(soft_float))]
                {
                    F32(self.0 $op other.0)
                }
            }
        }
    };
}

f32_operator!(Add, add, add, +);
f32_operator!(Sub, sub, sub, -);
f32_operator!(Mul, mul, mul, *);
f32_operator!(Div, div, div, /);

impl From<i32> for F32 {
    /// `v as f32`.
    #[inline(always)]
    fn from(v: i32) -> F32 {
        #[cfg(soft_float)]
        {
            F32(soft::from_i32(v))
        }
        #[cfg(not(soft_float))]
        {
            F32(v as f32)
        }
    }
}

impl From<u32> for F32 {
    /// `v as f32`.
    #[inline(always)]
    fn from(v: u32) -> F32 {
        #[cfg(soft_float)]
        {
            F32(soft::from_u32(v))
        }
        #[cfg(not(soft_float))]
        {
            F32(v as f32)
        }
    }
}

impl F32 {
    /// `|x|`: the sign bit cleared (no library call on any target).
    #[inline(always)]
    #[must_use]
    pub fn abs(self) -> F32 {
        F32(self.0.abs())
    }

    /// `x as i32` (see [`to_i32`]).
    #[inline(always)]
    #[must_use]
    pub fn to_i32(self) -> i32 {
        to_i32(self.0)
    }
}

impl PartialEq for F32 {
    /// Float equality: `-0 == +0`, NaN equal to nothing.
    #[inline(always)]
    fn eq(&self, other: &F32) -> bool {
        self.le(other) && other.le(self)
    }
}

impl PartialOrd for F32 {
    #[inline(always)]
    fn partial_cmp(&self, other: &F32) -> Option<core::cmp::Ordering> {
        use core::cmp::Ordering;
        match (self < other, other < self) {
            (true, _) => Some(Ordering::Less),
            (_, true) => Some(Ordering::Greater),
            _ if self == other => Some(Ordering::Equal),
            _ => None,
        }
    }

    #[inline(always)]
    fn lt(&self, other: &F32) -> bool {
        less(self.0, other.0)
    }

    #[inline(always)]
    fn le(&self, other: &F32) -> bool {
        less_or_equal(self.0, other.0)
    }

    #[inline(always)]
    fn gt(&self, other: &F32) -> bool {
        greater(self.0, other.0)
    }

    #[inline(always)]
    fn ge(&self, other: &F32) -> bool {
        less_or_equal(other.0, self.0)
    }
}

/// `a < b`: an integer comparison of the bits without an FPU (see [`order_key`](super::order_key)), where the
/// library's comparison is a call of about 30 instructions.
#[inline(always)]
pub(crate) fn less(a: f32, b: f32) -> bool {
    #[cfg(soft_float)]
    {
        soft::lt(a, b)
    }
    #[cfg(not(soft_float))]
    {
        a < b
    }
}

/// `a > b` (see [`less`]; written as `>` with an FPU, where the compiler then shares one
/// comparison between a `max` and a `min` of the same pair).
#[inline(always)]
pub(crate) fn greater(a: f32, b: f32) -> bool {
    #[cfg(soft_float)]
    {
        soft::lt(b, a)
    }
    #[cfg(not(soft_float))]
    {
        a > b
    }
}

/// `a <= b` (see [`less`]).
#[inline(always)]
fn less_or_equal(a: f32, b: f32) -> bool {
    #[cfg(soft_float)]
    {
        soft::le(a, b)
    }
    #[cfg(not(soft_float))]
    {
        a <= b
    }
}
