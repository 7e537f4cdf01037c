//! The benchmark's built-in stereo methods, by name: what each computes and its disparity map
//! of the left view, in the form every method's map is scored in (no value: `inf`).
//!
//! External methods (a program run on the pair's files) are the command's: running processes
//! with time limits and signal handling is a program's business, not a library's. Whatever
//! runs them hands its map to [`no_value_below_zero`] as the built-ins do.

use super::{lk_streak_disparity, streak_lk_params, StreakLkError};
use crate::detect::DetectParams;
use crate::repair::{estimate, EstimateError, RepairModel, StreakHandling};
use crate::sgm::SgmParams;
use streaks_image::GrayImage;

/// The built-in methods, by name, with what each is (the report's description).
pub const BUILT_INS: [(&str, &str); 3] = [
    (
        "sgm",
        "semi-global matching as `streaks disparity` computes it (census 7x7, 8 paths, \
         disparities 0-63, left-right check, median)",
    ),
    (
        "sgm-streaks",
        "sgm, then the streak repair: `streaks disparity --streaks repair` (values a learned \
         classifier of local stereo and appearance features finds fooled are replaced by the \
         surface around them where the kept values agree, else left without a value; no road \
         model)",
    ),
    (
        "lk",
        "the paper's per-row Lucas-Kanade along each detected streak's centre, as `streaks \
         analyze` measures it: values only on detected streak rows (a small valid share)",
    ),
];

/// What went wrong in a built-in method.
#[derive(Debug, thiserror::Error)]
pub enum MethodError {
    /// `sgm` or `sgm-streaks`.
    #[error(transparent)]
    Estimate(#[from] EstimateError),
    /// `lk`.
    #[error(transparent)]
    Lk(#[from] StreakLkError),
}

/// A built-in method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuiltIn {
    /// `sgm`: semi-global matching with its default parameters.
    Sgm,
    /// `sgm-streaks`: `sgm`, then the streak repair ([`StreakHandling::Repair`]).
    SgmStreaks,
    /// `lk`: the per-row Lucas-Kanade along the detected streaks ([`lk_streak_disparity`]).
    Lk,
}

impl BuiltIn {
    /// Every built-in method, in the order of [`BUILT_INS`].
    pub const ALL: [BuiltIn; 3] = [BuiltIn::Sgm, BuiltIn::SgmStreaks, BuiltIn::Lk];

    /// The built-in method called `name`.
    pub fn from_name(name: &str) -> Option<BuiltIn> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        BUILT_INS[self as usize].0
    }

    /// What it is, for the report.
    pub fn description(self) -> &'static str {
        BUILT_INS[self as usize].1
    }

    /// Its disparity of the left view of `left` and `right` (luminance), with every value
    /// that is not finite or not positive made `inf` ([`no_value_below_zero`]).
    pub fn disparity(self, left: &GrayImage, right: &GrayImage) -> Result<GrayImage, MethodError> {
        let mut disp = match self {
            BuiltIn::Sgm => estimate(left, right, &SgmParams::default(), None)?.disparity,
            BuiltIn::SgmStreaks => {
                estimate(
                    left,
                    right,
                    &SgmParams::default(),
                    Some((StreakHandling::Repair, RepairModel::shipped())),
                )?
                .disparity
            }
            BuiltIn::Lk => {
                lk_streak_disparity(left, right, &streak_lk_params(), &DetectParams::default())?
            }
        };
        no_value_below_zero(&mut disp);
        Ok(disp)
    }
}

/// Makes every disparity that is not finite or not positive `inf` (no value): the benchmark
/// scores every method's map so, whatever the method wrote there.
pub fn no_value_below_zero(disp: &mut GrayImage) {
    for v in &mut disp.data {
        if !(v.is_finite() && *v > 0.0) {
            *v = f32::INFINITY;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_no_value_is_inf() {
        for m in BuiltIn::ALL {
            assert_eq!(BuiltIn::from_name(m.name()), Some(m));
            assert!(!m.description().is_empty());
        }
        assert_eq!(BuiltIn::from_name("sgm-streaks"), Some(BuiltIn::SgmStreaks));
        assert_eq!(BuiltIn::from_name("net"), None);
        let mut d = GrayImage::from_vec(4, 1, vec![1.5, 0.0, -2.0, f32::NAN]).unwrap();
        no_value_below_zero(&mut d);
        assert_eq!(d.data[0], 1.5);
        assert!(d.data[1..].iter().all(|v| *v == f32::INFINITY));
    }
}
