//! The one check that two images (or an image and a mask, or a map and the size a rig gives)
//! have the same size, and its error, which every crate's error type wraps.

/// Two images that must have the same size do not; names both, so that a user knows which
/// input to fix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error(
    "image sizes differ: {first} is {}x{}, {second} is {}x{}",
    .first_size.0,
    .first_size.1,
    .second_size.0,
    .second_size.1
)]
pub struct SizeMismatch {
    /// The first image (for example `A`, `the left image`).
    pub first: &'static str,
    /// Its width and height in pixels.
    pub first_size: (usize, usize),
    /// The other image.
    pub second: &'static str,
    /// Its width and height in pixels.
    pub second_size: (usize, usize),
}

/// `Ok` when `first_size` and `second_size` (width, height) are equal, else the
/// [`SizeMismatch`] that names `first` and `second`.
pub fn ensure_same_size(
    first: &'static str,
    first_size: (usize, usize),
    second: &'static str,
    second_size: (usize, usize),
) -> Result<(), SizeMismatch> {
    if first_size == second_size {
        Ok(())
    } else {
        Err(SizeMismatch {
            first,
            first_size,
            second,
            second_size,
        })
    }
}

/// [`ensure_same_size`] of the two views of a stereo pair (width, height), named the left
/// and the right image.
pub fn ensure_pair_size(left: (usize, usize), right: (usize, usize)) -> Result<(), SizeMismatch> {
    ensure_same_size("the left image", left, "the right image", right)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_sizes_pass_and_others_name_both_images() {
        assert_eq!(ensure_same_size("A", (4, 3), "B", (4, 3)), Ok(()));
        let err = ensure_same_size("A", (4, 4), "B", (4, 5)).unwrap_err();
        assert_eq!(err.to_string(), "image sizes differ: A is 4x4, B is 4x5");
        assert!(ensure_same_size("A", (4, 3), "B", (3, 4)).is_err());
        assert_eq!(ensure_pair_size((2, 1), (2, 1)), Ok(()));
        let err = ensure_pair_size((2, 1), (1, 2)).unwrap_err();
        assert_eq!(err.first_size, (2, 1));
        assert_eq!(err.second, "the right image");
    }
}
