//! Time and camera motion: the shutter interval and the rig's velocity.
//!
//! Time is in seconds relative to the reference time 0, at which the scene's cameras stand
//! where the scene puts them, rain drops are where they were placed, and the ground-truth
//! layers (depth, normal, albedo, material, disparity) are taken. A camera sample of a render
//! whose shutter is open for a nonzero interval draws its time uniformly in `[open, close)`
//! (a box shutter), and its ray starts at the camera moved by `rig_velocity * t` (a
//! translation: the camera keeps its orientation). The ray carries its time
//! ([`crate::geometry::Ray::time`]) and every ray of its path inherits it, so moving geometry
//! (rain drops) is seen where it is at that instant. A closed shutter (`open == close`, the
//! default) draws no random number and renders exactly as a renderer without time does.

use glam::Vec3;

/// The shutter interval (seconds, relative to the reference time 0) and the camera rig's
/// velocity (m/s, world space). [`Default`]: no motion blur (`0, 0`, at rest).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// When the shutter opens, seconds.
    pub open: f32,
    /// When it closes, seconds (at least `open`).
    pub close: f32,
    /// The rig's velocity in world space, m/s (both eyes of a stereo pair move together).
    pub rig_velocity: Vec3,
}

impl Motion {
    /// A shutter of `seconds` centred on the reference time (`open = -s/2`, `close = s/2`)
    /// with the rig moving at `rig_velocity`.
    pub fn centred(seconds: f32, rig_velocity: Vec3) -> Self {
        Motion {
            open: -0.5 * seconds,
            close: 0.5 * seconds,
            rig_velocity,
        }
    }

    /// Whether the shutter is open for a nonzero interval (camera samples then draw a time).
    #[inline]
    pub fn is_blurred(&self) -> bool {
        self.close > self.open
    }

    /// The time of a camera sample with uniform variate `u` in `[0, 1)`.
    #[inline]
    pub fn time(&self, u: f32) -> f32 {
        self.open + u * (self.close - self.open)
    }

    /// The largest `|t|` the shutter reaches (how far from their reference positions things
    /// can move during it, per unit of speed).
    #[inline]
    pub fn max_abs_time(&self) -> f32 {
        self.open.abs().max(self.close.abs())
    }

    /// Checks that the times are finite with `open <= close` and the velocity finite; the
    /// reason otherwise.
    pub fn check(&self) -> Result<(), String> {
        if !(self.open.is_finite() && self.close.is_finite()) || self.open > self.close {
            return Err(format!(
                "the shutter must open before it closes, at finite times (got {} to {})",
                self.open, self.close
            ));
        }
        if !self.rig_velocity.is_finite() {
            return Err(format!(
                "the rig velocity must be finite (got {})",
                self.rig_velocity
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centred_shutter_and_times() {
        let m = Motion::centred(1.0 / 60.0, Vec3::X);
        assert!(m.is_blurred());
        assert_eq!(m.time(0.0), -1.0 / 120.0);
        assert!((m.time(0.5)).abs() < 1e-9);
        assert_eq!(m.max_abs_time(), 1.0 / 120.0);
        assert!(!Motion::default().is_blurred());
        assert!(m.check().is_ok());
        let backwards = Motion {
            open: 1.0,
            close: 0.0,
            ..Motion::default()
        };
        assert!(backwards.check().is_err());
    }
}
