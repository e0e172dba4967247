//! Square root, sine and cosine computed in single precision, for FPUs that have no other.
//!
//! `libm`'s `sinf`, `cosf`, `sincosf` and `tanf` (ports of musl's) evaluate their polynomials
//! in `f64`; on a single-precision FPU such as the Cortex-M4F's or M7's every one of those
//! operations is a call into software floating point (`__aeabi_dmul`, `__aeabi_dadd`). Its
//! `sqrtf` is an integer routine on Arm, where the FPU has a square-root instruction. The
//! kinematics take a sine and cosine per joint per iteration and the projection a square root
//! per link, so on the emulated Cortex-M7 these took about a tenth of an iteration
//! (`docs/performance.md`, "Single precision on the board").
//!
//! Here the same functions stay in `f32`:
//! - [`sin_cos`]: Cody–Waite reduction by π/2 in three parts, then the Cephes single-precision
//!   polynomials on [−π/4, π/4]. Within 8·10⁻⁸ of the exact values for |x| ≤ 100 (about
//!   0.7 ulp of 1; `libm`'s: 3·10⁻⁸; joint angles lie within ±π), 2·10⁻⁷ up to
//!   [`REDUCED_UP_TO`], tested against `f64` below. Beyond that, and for NaN or infinity,
//!   `libm` answers (a NaN stays NaN).
//! - [`sqrt`]: the FPU's `vsqrt.f32` on an Arm target with a hardware FPU (`eabihf`),
//!   `libm::sqrtf` elsewhere (on x86-64 already the SSE instruction). Both are correctly
//!   rounded, so the board and the host still agree bit for bit.
//!
//! The host and the board call the same functions, so their states stay equal bit for bit.

/// The largest |x| (radians) reduced here; beyond it `libm`'s exact reduction is used.
pub const REDUCED_UP_TO: f32 = 8192.0;

/// `(sin x, cos x)` of `x` in radians, in `f32` arithmetic (see the module's accuracy).
pub fn sin_cos(x: f32) -> (f32, f32) {
    // NaN and the infinities go to libm too.
    if x.is_nan() || x.abs() > REDUCED_UP_TO {
        return libm::sincosf(x);
    }
    // π/2 in three parts; the first two have few enough mantissa bits that `quadrant × part`
    // is exact for every quadrant up to REDUCED_UP_TO.
    const PI_2_HIGH: f32 = 1.570_312_5;
    const PI_2_MIDDLE: f32 = 4.837_513e-4;
    const PI_2_LOW: f32 = 7.549_79e-8;
    let q = x * core::f32::consts::FRAC_2_PI;
    let quadrant = (q + if q >= 0.0 { 0.5 } else { -0.5 }) as i32;
    let j = quadrant as f32;
    let r = ((x - j * PI_2_HIGH) - j * PI_2_MIDDLE) - j * PI_2_LOW;
    let z = r * r;
    let sin_r = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * r + r;
    let cos_r =
        ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    match quadrant & 3 {
        0 => (sin_r, cos_r),
        1 => (cos_r, -sin_r),
        2 => (-sin_r, -cos_r),
        _ => (-cos_r, sin_r),
    }
}

/// `sin x`, `x` in radians ([`sin_cos`]).
pub fn sin(x: f32) -> f32 {
    sin_cos(x).0
}

/// `cos x`, `x` in radians ([`sin_cos`]).
pub fn cos(x: f32) -> f32 {
    sin_cos(x).1
}

/// `tan x`, `x` in radians, as `sin x / cos x` ([`sin_cos`]).
pub fn tan(x: f32) -> f32 {
    let (s, c) = sin_cos(x);
    s / c
}

/// The square root, correctly rounded (NaN for negative `x`).
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
pub fn sqrt(x: f32) -> f32 {
    let root: u32;
    // SAFETY: three register instructions of the FPU every `eabihf` target has; they touch
    // no memory and no flags, and the one FPU register they use, s15 (caller-saved), is
    // declared clobbered.
    unsafe {
        core::arch::asm!(
            "vmov s15, {x}",
            "vsqrt.f32 s15, s15",
            "vmov {root}, s15",
            x = in(reg) x.to_bits(),
            root = lateout(reg) root,
            out("s15") _,
            options(pure, nomem, nostack, preserves_flags),
        );
    }
    f32::from_bits(root)
}

/// The square root, correctly rounded (NaN for negative `x`).
#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// nalgebra's `norm`, `normalize` and `try_normalize` for `f32` vectors, with [`sqrt`]
/// (nalgebra's own take `libm::sqrtf`); the same values bit for bit.
pub trait Length: Sized {
    /// The Euclidean length.
    fn length(&self) -> f32;
    /// The vector divided by its length (not finite when that is 0).
    fn normalized(&self) -> Self;
    /// The vector divided by its length, or `None` when that is at most `min_length`.
    fn try_normalized(&self, min_length: f32) -> Option<Self>;
}

impl<const D: usize> Length for nalgebra::SVector<f32, D> {
    fn length(&self) -> f32 {
        sqrt(self.norm_squared())
    }

    fn normalized(&self) -> Self {
        self / self.length()
    }

    fn try_normalized(&self, min_length: f32) -> Option<Self> {
        let n = self.length();
        (n > min_length).then(|| self / n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest difference from `f64`'s sine and cosine over `n` points of `[from, to]`.
    fn worst_error(from: f32, to: f32, n: u32) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..=n {
            let x = from + (to - from) * (i as f32 / n as f32);
            let (s, c) = sin_cos(x);
            let x64 = f64::from(x);
            worst = worst
                .max((f64::from(s) - libm::sin(x64)).abs())
                .max((f64::from(c) - libm::cos(x64)).abs());
        }
        worst
    }

    #[test]
    fn sine_and_cosine_are_within_eight_hundred_millionths() {
        assert!(worst_error(-4.0, 4.0, 400_000) < 8e-8);
        assert!(worst_error(-100.0, 100.0, 400_000) < 8e-8);
        assert!(worst_error(REDUCED_UP_TO - 10.0, REDUCED_UP_TO, 10_000) < 2e-7);
    }

    #[test]
    fn quadrant_boundaries_and_exact_points() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        for k in -8..=8 {
            let x = k as f32 * core::f32::consts::FRAC_PI_4;
            let (s, c) = sin_cos(x);
            let (ls, lc) = libm::sincosf(x);
            assert!((s - ls).abs() <= 1.2e-7 && (c - lc).abs() <= 1.2e-7, "{x}");
        }
    }

    #[test]
    fn beyond_the_reduction_and_non_finite_go_to_libm() {
        assert_eq!(sin_cos(1.0e6), libm::sincosf(1.0e6));
        assert!(sin_cos(f32::NAN).0.is_nan() && sin_cos(f32::NAN).1.is_nan());
        assert!(sin_cos(f32::INFINITY).0.is_nan());
        assert!(tan(f32::NAN).is_nan());
    }

    #[test]
    fn tan_is_sine_over_cosine() {
        for x in [-1.4f32, -0.5, 0.0, 0.52, 1.2] {
            assert!((tan(x) - libm::tanf(x)).abs() <= 4e-7 * libm::tanf(x).abs().max(1.0));
        }
    }

    #[test]
    fn sqrt_and_length_are_correctly_rounded() {
        for x in [0.0f32, 1e-30, 0.25, 2.0, 3.0, 1e20, f32::MAX] {
            assert_eq!(sqrt(x).to_bits(), libm::sqrtf(x).to_bits());
        }
        assert!(sqrt(-1.0).is_nan() && sqrt(f32::NAN).is_nan());
        let v = nalgebra::Vector3::new(3.0f32, 4.0, 1.2);
        assert_eq!(v.length().to_bits(), v.norm().to_bits());
        assert_eq!(v.normalized(), v.normalize());
        assert_eq!(v.try_normalized(1e-6), v.try_normalize(1e-6));
        assert_eq!(
            nalgebra::Vector2::new(1e-7f32, 0.0).try_normalized(1e-6),
            None
        );
    }
}
