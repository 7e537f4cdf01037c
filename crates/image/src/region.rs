//! Rectangles of pixels, and the one parser of their command-line form `[name=]x0,y0,x1,y1`
//! (used by `streaks compare`, `streaks lk` and `streaks analyze`).

use crate::ImageError;
use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// A rectangle of pixel indices, half-open: columns `[x0, x1)`, rows `[y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Region {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

/// A [`Region`] with a name, for reports and file names. Serialised flat:
/// `{"name": ..., "x0": ..., "y0": ..., "x1": ..., "y1": ...}`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct NamedRegion {
    /// Its name: letters, digits, `_` and `-` (empty where none was given).
    pub name: String,
    /// The pixels.
    #[serde(flatten)]
    pub region: Region,
}

impl Region {
    /// The whole of a `width` x `height` image.
    pub fn whole(width: usize, height: usize) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Its width in pixels.
    #[inline]
    pub fn width(&self) -> usize {
        self.x1.saturating_sub(self.x0)
    }

    /// Its height in pixels.
    #[inline]
    pub fn height(&self) -> usize {
        self.y1.saturating_sub(self.y0)
    }

    /// Whether it holds no pixel.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.width() == 0 || self.height() == 0
    }

    /// The image x coordinate of its centre column.
    #[inline]
    pub fn centre_x(&self) -> f32 {
        0.5 * (self.x0 + self.x1) as f32
    }

    /// Whether it is non-empty and lies within a `width` x `height` image.
    #[inline]
    pub fn fits(&self, width: usize, height: usize) -> bool {
        !self.is_empty() && self.x1 <= width && self.y1 <= height
    }

    /// [`Region::fits`] as an error naming the region `name`.
    pub fn check_fits(&self, name: &str, width: usize, height: usize) -> Result<(), ImageError> {
        if self.fits(width, height) {
            return Ok(());
        }
        Err(ImageError::RegionOutside {
            name: name.to_owned(),
            x0: self.x0,
            y0: self.y0,
            x1: self.x1,
            y1: self.y1,
            width,
            height,
        })
    }
}

impl FromStr for Region {
    type Err = ImageError;

    /// Parses `x0,y0,x1,y1`: four non-negative pixel indices with `x1 > x0` and `y1 > y0`.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        parse_coordinates(text, text, UNNAMED)
    }
}

impl FromStr for NamedRegion {
    type Err = ImageError;

    /// Parses `x0,y0,x1,y1` or `name=x0,y0,x1,y1` (an unnamed region gets the empty name; the
    /// caller names it). A name is letters, digits, `_` and `-`, so it can name a file.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let (name, coords) = match text.split_once('=') {
            Some((n, c)) => (n.trim(), c),
            None => ("", text),
        };
        let name_ok = name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !name_ok || (name.is_empty() && text.contains('=')) {
            return Err(bad(
                text,
                &format!("the name {name:?} must be letters, digits, _ or -"),
                NAMED,
            ));
        }
        Ok(NamedRegion {
            name: name.to_owned(),
            region: parse_coordinates(text, coords, NAMED)?,
        })
    }
}

/// The form of a [`Region`].
const UNNAMED: &str = "x0,y0,x1,y1";
/// The form of a [`NamedRegion`].
const NAMED: &str = "[name=]x0,y0,x1,y1";

fn bad(text: &str, reason: &str, expected: &'static str) -> ImageError {
    ImageError::BadRegion {
        text: text.to_owned(),
        reason: reason.to_owned(),
        expected,
    }
}

/// The four coordinates of `coords`, part of `text` (for the message), which has the form
/// `expected`.
fn parse_coordinates(
    text: &str,
    coords: &str,
    expected: &'static str,
) -> Result<Region, ImageError> {
    let bad = |reason: &str| bad(text, reason, expected);
    let v: Vec<usize> = coords
        .split(',')
        .map(|s| s.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|e| bad(&format!("not a pixel coordinate ({e})")))?;
    let [x0, y0, x1, y1] = v[..] else {
        return Err(bad(&format!("needs four numbers, got {}", v.len())));
    };
    if x1 <= x0 || y1 <= y0 {
        return Err(bad("empty: x1 must exceed x0 and y1 must exceed y0"));
    }
    Ok(Region { x0, y0, x1, y1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_named_and_unnamed_regions() {
        let r: Region = "1, 2,30,40".parse().unwrap();
        assert_eq!(
            r,
            Region {
                x0: 1,
                y0: 2,
                x1: 30,
                y1: 40
            }
        );
        assert_eq!((r.width(), r.height(), r.centre_x()), (29, 38, 15.5));
        let n: NamedRegion = "road_1=0,0,5,5".parse().unwrap();
        assert_eq!(n.name, "road_1");
        assert_eq!(n.region, Region::whole(5, 5));
        let n: NamedRegion = "0,0,5,5".parse().unwrap();
        assert_eq!(n.name, "");
        for (text, why) in [
            ("1,2,3", "four numbers"),
            ("a=1,2,x,4", "pixel coordinate"),
            ("5,0,5,9", "empty"),
            ("-1,0,5,9", "pixel coordinate"),
            ("my road=0,0,5,5", "letters"),
            ("=0,0,5,5", "letters"),
        ] {
            let err = text.parse::<NamedRegion>().unwrap_err().to_string();
            assert!(err.contains(why) && err.contains(text), "{text}: {err}");
        }
    }

    #[test]
    fn fits_inside_the_image_only() {
        let r = Region {
            x0: 2,
            y0: 2,
            x1: 10,
            y1: 8,
        };
        assert!(r.fits(10, 8) && !r.fits(9, 8));
        let err = r.check_fits("sign", 9, 8).unwrap_err().to_string();
        assert!(err.contains("sign") && err.contains("9x8"), "{err}");
        assert!(!Region::whole(0, 5).fits(0, 5));
    }

    #[test]
    fn named_regions_serialise_flat() {
        let n = NamedRegion {
            name: "a".into(),
            region: Region::whole(3, 4),
        };
        let json = serde_json::to_string(&n).unwrap();
        assert_eq!(json, r#"{"name":"a","x0":0,"y0":0,"x1":3,"y1":4}"#);
        assert_eq!(serde_json::from_str::<NamedRegion>(&json).unwrap(), n);
    }
}
