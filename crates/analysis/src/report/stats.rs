//! The statistics of the report: least-squares lines ([`fit_line`]), measured against
//! predicted disparity ([`compare`]), and the spans and medians of the table.

use super::RowRecord;
use serde::Serialize;

/// A least-squares line `y = intercept + slope x` with the slope's standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LineFit {
    /// Slope.
    pub slope: f64,
    /// Intercept.
    pub intercept: f64,
    /// Standard error of the slope (NaN with fewer than 3 points).
    pub slope_se: f64,
    /// Number of points.
    pub n: usize,
}

/// Fits a line to `(x, y)` points; `None` with fewer than 2 distinct x.
pub fn fit_line(points: &[(f64, f64)]) -> Option<LineFit> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / nf;
    let my = points.iter().map(|p| p.1).sum::<f64>() / nf;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let slope_se = if n > 2 {
        let sse: f64 = points
            .iter()
            .map(|p| (p.1 - intercept - slope * p.0).powi(2))
            .sum();
        (sse / (nf - 2.0) / sxx).sqrt()
    } else {
        f64::NAN
    };
    Some(LineFit {
        slope,
        intercept,
        slope_se,
        n,
    })
}

/// Measured against predicted over the rows that have both.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Rows with both values.
    pub rows: usize,
    /// RMS of measured minus predicted, pixels.
    pub rms_px: f64,
    /// RMS of measured minus predicted, degrees.
    pub rms_deg: f64,
    /// Mean of measured minus predicted, pixels.
    pub bias_px: f64,
    /// Largest minus smallest measured disparity, pixels.
    pub measured_span_px: f64,
    /// Largest minus smallest predicted disparity, pixels.
    pub predicted_span_px: f64,
    /// Line fit of measured disparity (px) against row.
    pub measured_fit: Option<LineFit>,
    /// Line fit of predicted disparity (px) against row.
    pub predicted_fit: Option<LineFit>,
    /// Whether the slopes agree within twice their combined standard error.
    pub slope_agrees: bool,
}

/// Largest minus smallest value (`-inf` for none).
pub(super) fn span(v: impl Iterator<Item = f64> + Clone) -> f64 {
    v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
}

/// Compares the measured and predicted disparities of `rows`.
pub fn compare(rows: &[RowRecord]) -> Option<Comparison> {
    compare_with(rows, |r| r.predicted_px.zip(r.predicted_deg))
}

/// Compares the measured disparities of `rows` with the prediction `model` gives a row (in
/// pixels and degrees): [`compare`] for Eq. 4, the same statistics for the streak-centre
/// model.
pub fn compare_with(
    rows: &[RowRecord],
    model: impl Fn(&RowRecord) -> Option<(f64, f64)>,
) -> Option<Comparison> {
    let both: Vec<(&RowRecord, f64, f64)> = rows
        .iter()
        .filter(|r| r.measured_px.is_finite())
        .filter_map(|r| model(r).map(|(px, deg)| (r, px, deg)))
        .collect();
    if both.is_empty() {
        return None;
    }
    let n = both.len() as f64;
    let diff_px = both.iter().map(|(r, px, _)| r.measured_px - px);
    let rms_px = (diff_px.clone().map(|d| d * d).sum::<f64>() / n).sqrt();
    let bias_px = diff_px.sum::<f64>() / n;
    let rms_deg = (both
        .iter()
        .map(|(r, _, deg)| (r.measured_deg - deg).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let measured: Vec<(f64, f64)> = both
        .iter()
        .map(|(r, _, _)| (r.row as f64, r.measured_px))
        .collect();
    let predicted: Vec<(f64, f64)> = both.iter().map(|(r, px, _)| (r.row as f64, *px)).collect();
    let (mf, pf) = (fit_line(&measured), fit_line(&predicted));
    let slope_agrees = match (mf, pf) {
        (Some(m), Some(p)) => {
            let se = (m.slope_se.powi(2) + p.slope_se.powi(2)).sqrt();
            se.is_finite() && (m.slope - p.slope).abs() <= 2.0 * se
        }
        _ => false,
    };
    Some(Comparison {
        rows: both.len(),
        rms_px,
        rms_deg,
        bias_px,
        measured_span_px: span(measured.iter().map(|p| p.1)),
        predicted_span_px: span(predicted.iter().map(|p| p.1)),
        measured_fit: mf,
        predicted_fit: pf,
        slope_agrees,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_fit_recovers_a_line_and_its_uncertainty() {
        let pts: Vec<(f64, f64)> = (0..20).map(|i| (i as f64, 2.0 - 0.5 * i as f64)).collect();
        let f = fit_line(&pts).unwrap();
        assert!((f.slope + 0.5).abs() < 1e-12 && (f.intercept - 2.0).abs() < 1e-12);
        assert!(f.slope_se < 1e-9);
        assert!(fit_line(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
    }
}
