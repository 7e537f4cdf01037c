//! The font for plots: DejaVu Sans (Bitstream Vera licence, `fonts/DejaVuSans-LICENSE.txt`),
//! compiled into the crate and registered with plotters' `ab_glyph` backend, so plots need no
//! system fonts. Plotters must be built with `default-features = false` and the `ab_glyph`
//! feature (the workspace's setting): its `ttf` feature would look for system fonts instead.

use crate::error::StereoError;
use plotters::style::FontStyle;
use std::sync::OnceLock;

/// Registers DejaVu Sans as plotters' `"sans-serif"` family (once per process); call it before
/// drawing text with plotters.
pub fn register_sans_serif() -> Result<(), StereoError> {
    static FONT: OnceLock<bool> = OnceLock::new();
    let ok = *FONT.get_or_init(|| {
        plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../fonts/DejaVuSans.ttf"),
        )
        .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(StereoError::Parameter {
            name: "font",
            reason: "the bundled DejaVu Sans font did not load".into(),
        })
    }
}
