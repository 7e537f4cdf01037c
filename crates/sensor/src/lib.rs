//! # streaks-sensor
//!
//! A camera for the renders: what a car's camera makes of the linear radiance image the path
//! tracer computes. One concept per module:
//!
//! - [`profile`]: [`SensorProfile`], the camera's numbers read from TOML with a default for
//!   every field, and the embedded presets ([`profile::PRESETS`]);
//! - [`lens`]: the point spread function (aperture diffraction and a scattering veil, energy
//!   conserving, applied by FFT) and natural vignetting;
//! - [`sensor`]: the linear sensor of EMVA 1288: radiance to electrons (the camera equation),
//!   shot noise, dark current, full well, read noise, black level and the ADC;
//! - [`camera`]: [`capture`], the whole chain from radiance to raw DN ([`Capture`]);
//! - [`develop`](mod@develop): the one tone curve from DN to 8-bit sRGB;
//! - [`error`]: [`SensorError`], naming the profile and the field.
//!
//! ```
//! use glam::Vec3;
//! use streaks_image::RgbImage;
//! use streaks_sensor::{capture, SensorProfile};
//!
//! let profile = SensorProfile::resolve("automotive_linear")?;
//! // A road at 1 cd/m^2 (1/683 W/(m^2 sr)) seen by a camera with a focal length of 500 px.
//! let road = RgbImage::from_fn(64, 48, |_, _| Vec3::splat(1.0 / 683.0));
//! let raw = capture(&profile, &road, 500.0, 0.0, 7)?;
//! let mean = raw.dn.pixels.iter().map(|p| p.y as f64).sum::<f64>() / (64.0 * 48.0);
//! assert!(mean > profile.black_level_dn + 10.0);
//! let png = raw.develop();
//! assert_eq!(png.dimensions(), (64, 48));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

pub mod camera;
pub mod develop;
pub mod error;
pub mod lens;
pub mod profile;
pub mod sensor;

pub use camera::{capture, Capture};
pub use error::SensorError;
pub use profile::SensorProfile;
