//! `OUT/index.html` of `streaks benchmark`: one self-contained page (inline CSS, inline SVG
//! bar charts, thumbnails as base64 PNG data URIs), readable offline.

use super::report::{FailureKind, MethodScore, Report, REGIONS};
use crate::html::{bar_chart, esc, Bar, CSS};
use anyhow::Result;
use std::fmt::Write;
use streaks_analysis::benchmark::breakdown::{
    BinErrors, Breakdown, DISTANCE_BINS, STREAK_LENGTH_BINS,
};
use streaks_analysis::benchmark::{
    error_colour, ERROR_MAP_RANGE_PX, NO_ESTIMATE_RGB, NO_TRUTH_RGB,
};
use streaks_analysis::sgm::DisparityErrors;

/// Widest thumbnail, pixels.
const THUMB_WIDTH: u32 = 256;

/// Bar colours of the methods, in order (Tableau 10).
const PALETTE: [&str; 10] = [
    "#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#ff9da7",
    "#9c755f", "#bab0ac",
];

/// The thumbnails of one sample: its left image and each method's error map, as data URIs.
pub struct SampleThumbs {
    id: String,
    left: String,
    maps: Vec<(String, String)>,
}

/// `img` scaled to at most [`THUMB_WIDTH`] wide, as a PNG data URI.
fn thumb_uri(img: &image::RgbImage, filter: image::imageops::FilterType) -> Result<String> {
    let (w, h) = img.dimensions();
    let small = if w > THUMB_WIDTH {
        let th = ((h as f64 * THUMB_WIDTH as f64 / w as f64).round() as u32).max(1);
        image::imageops::resize(img, THUMB_WIDTH, th, filter)
    } else {
        img.clone()
    };
    let png = streaks_image::png::png_bytes(&small)?;
    Ok(format!("data:image/png;base64,{}", base64::encode(png)))
}

impl SampleThumbs {
    /// The thumbnails of sample `id`: its left image and `(method, error map)`s.
    pub fn new(
        id: &str,
        left: &image::RgbImage,
        maps: &[(String, image::RgbImage)],
    ) -> Result<Self> {
        use image::imageops::FilterType;
        Ok(Self {
            id: id.to_string(),
            left: thumb_uri(left, FilterType::Triangle)?,
            maps: maps
                .iter()
                .map(|(m, img)| Ok((m.clone(), thumb_uri(img, FilterType::Nearest)?)))
                .collect::<Result<_>>()?,
        })
    }
}

fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

/// A cell of a figure over the pixels with a value: `–` when there are none.
fn cell(e: &DisparityErrors, text: String) -> String {
    if e.valid_pixels == 0 {
        "<td class=\"none\" title=\"no values\">–</td>".to_string()
    } else {
        format!("<td>{text}</td>")
    }
}

/// `s` escaped, with `code` spans in backticks shown as code.
fn esc_code(s: &str) -> String {
    esc(s)
        .split('`')
        .enumerate()
        .map(|(i, part)| {
            if i % 2 == 1 {
                format!("<code>{part}</code>")
            } else {
                part.to_string()
            }
        })
        .collect()
}

/// A cell of a figure of a region a sample may lack: `n/a` when the samples have no mask for
/// it (not available, not zero), else as [`cell`].
fn region_cell(e: Option<&DisparityErrors>, text: impl Fn(&DisparityErrors) -> String) -> String {
    match e {
        None => "<td class=\"none\" title=\"not available: the samples have no mask for this \
                 region\">n/a</td>"
            .to_string(),
        Some(e) => cell(e, text(e)),
    }
}

/// The phantom-hole rate cell of a score: `n/a` without road masks, `–` without values (a
/// failure).
fn phantom_cell(m: &MethodScore) -> String {
    match (m.phantom_hole_rate, m.errors.road_surface) {
        (Some(v), _) => format!("<td>{}</td>", pct(v)),
        (None, None) => region_cell(None, |_| String::new()),
        (None, Some(_)) => "<td class=\"none\" title=\"no values\">–</td>".to_string(),
    }
}

/// A time cell: `not timed` for maps made beforehand.
fn seconds_cell(v: Option<f64>) -> String {
    match v {
        Some(v) => format!("<td>{v:.2}</td>"),
        None => "<td class=\"none\" title=\"maps made beforehand\">not timed</td>".to_string(),
    }
}

/// The failed-samples cell of a summary row: `–` when none.
fn failed_cell(m: &MethodScore) -> String {
    match m.failed {
        0 => "<td class=\"none\">–</td>".to_string(),
        n if n == m.samples => format!("<td class=\"fail\">all {n}: no score</td>"),
        n => format!("<td class=\"fail\">{n} of {}</td>", m.samples),
    }
}

/// The columns of a region table.
fn region_row(out: &mut String, method: &str, colour: &str, e: &DisparityErrors) {
    let _ = writeln!(
        out,
        "<tr><td><span class=\"swatch\" style=\"background:{colour}\"></span>{}</td>\
         {}{}{}{}{}<td>{}</td><td>{}</td><td>{}</td></tr>",
        esc(method),
        cell(e, format!("{:.3}", e.mean_abs)),
        cell(e, pct(e.bad_1)),
        cell(e, pct(e.bad_2)),
        cell(e, pct(e.bad_3)),
        cell(e, pct(e.d1)),
        pct(e.density),
        pct(e.below_1px),
        e.truth_pixels
    );
}

/// The legend of the error maps (inline SVG).
fn legend() -> String {
    let mut s = String::from(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"46\" role=\"img\" \
         aria-label=\"error map legend\"><defs><linearGradient id=\"err\">",
    );
    for k in 0..=20 {
        let e = -ERROR_MAP_RANGE_PX + 2.0 * ERROR_MAP_RANGE_PX * k as f32 / 20.0;
        let [r, g, b] = error_colour(e);
        let _ = write!(
            s,
            "<stop offset=\"{}%\" stop-color=\"rgb({r},{g},{b})\"/>",
            k * 5
        );
    }
    s.push_str(
        "</linearGradient></defs><rect x=\"0\" y=\"4\" width=\"360\" height=\"14\" rx=\"2\" \
         fill=\"url(#err)\" stroke=\"#ccc\"/>",
    );
    let r = ERROR_MAP_RANGE_PX;
    for (x, anchor, label) in [
        (0.0, "start", format!("−{r} px or less: farther")),
        (180.0, "middle", "0".to_string()),
        (360.0, "end", format!("nearer: +{r} px or more")),
    ] {
        let _ = write!(
            s,
            "<text x=\"{x}\" y=\"34\" font-size=\"12\" text-anchor=\"{anchor}\" \
             fill=\"#5b6475\">{}</text>",
            esc(&label)
        );
    }
    for (x, rgb, label) in [
        (390.0, NO_ESTIMATE_RGB, "no estimate"),
        (500.0, NO_TRUTH_RGB, "no ground truth"),
    ] {
        let _ = write!(
            s,
            "<rect x=\"{x}\" y=\"4\" width=\"14\" height=\"14\" rx=\"2\" \
             fill=\"rgb({},{},{})\" stroke=\"#ccc\"/><text x=\"{tx}\" y=\"16\" font-size=\"12\" \
             fill=\"#5b6475\">{label}</text>",
            rgb[0],
            rgb[1],
            rgb[2],
            tx = x + 20.0
        );
    }
    s.push_str("</svg>");
    s
}

/// The region's errors of a method's score.
fn region_of<'a>(m: &'a MethodScore, region: &str) -> Option<&'a DisparityErrors> {
    let e = &m.errors;
    match region {
        "all" => Some(&e.all),
        "streak" => e.streak.as_ref(),
        "non_streak" => e.non_streak.as_ref(),
        "road" => e.road.as_ref(),
        "off_road" => e.off_road.as_ref(),
        "road_surface" => e.road_surface.as_ref(),
        "non_occluded" => e.non_occluded.as_ref(),
        _ => None,
    }
}

/// A failure kind as the report spells it.
fn kind_name(kind: FailureKind) -> String {
    serde_json::to_value(kind)
        .ok()
        .and_then(|v| v.as_str().map(|s| s.replace('_', " ")))
        .unwrap_or_default()
}

/// The failures section: per method, each failed sample with the kind, the reason and the
/// end of the command's stderr. Nothing when no method failed.
fn failures(o: &mut String, report: &Report) {
    if report.summary.iter().all(|m| m.failed == 0) {
        return;
    }
    let _ = write!(
        o,
        "<section id=\"failures\"><h2>Failures</h2><p class=\"note\">{}.</p>",
        esc_code(report.failure_scoring)
    );
    for m in report.summary.iter().filter(|m| m.failed > 0) {
        let _ = write!(
            o,
            "<h3>{}: failed on {} of {} samples</h3><table class=\"failures\"><tr>\
             <th>sample</th><th class=\"l\">kind</th><th class=\"l\">reason</th></tr>",
            esc(&m.method),
            m.failed,
            m.samples
        );
        for s in &report.samples {
            for r in s.results.iter().filter(|r| r.method == m.method) {
                let Some(f) = &r.failure else { continue };
                let tail: String = [("stderr", &f.stderr_tail), ("stdout", &f.stdout_tail)]
                    .iter()
                    .filter(|(_, t)| !t.is_empty())
                    .map(|(stream, t)| {
                        format!(
                            "<details><summary>end of its {stream}</summary><pre>{}</pre>\
                             </details>",
                            esc(t)
                        )
                    })
                    .collect();
                let _ = write!(
                    o,
                    "<tr><td>{}</td><td class=\"l\">{}</td><td class=\"reason\">{}{tail}</td>\
                     </tr>",
                    esc(&s.id),
                    esc(&kind_name(f.kind)),
                    esc(&f.reason)
                );
            }
        }
        o.push_str("</table>");
    }
    o.push_str("</section>\n");
}

/// A cell of a bin's figure: `n/a` when no pixel with ground truth falls in the bin (not
/// available, not zero), else as [`cell`].
fn bin_cell(e: Option<&DisparityErrors>, text: impl Fn(&DisparityErrors) -> String) -> String {
    match e {
        None => "<td class=\"none\" title=\"not available: no pixel with a ground truth in \
                 this bin\">n/a</td>"
            .to_string(),
        Some(e) => cell(e, text(e)),
    }
}

/// The errors of bin `k` of a breakdown's list.
fn bin_of(bins: &Option<Vec<BinErrors>>, k: usize) -> Option<&DisparityErrors> {
    bins.as_ref()?.get(k)?.errors.as_ref()
}

/// The pixels of bin `k` over the methods' breakdowns (the same for every method: the ground
/// truth's), as a header note.
fn bin_pixels(
    report: &Report,
    list: fn(&Breakdown) -> &Option<Vec<BinErrors>>,
    k: usize,
) -> String {
    let n = report
        .summary
        .iter()
        .find_map(|m| bin_of(list(&m.breakdown), k))
        .map_or(0, |e| e.truth_pixels);
    format!("{n} px")
}

/// The breakdown sections: by condition (a dataset's samples), by streak length, by
/// distance; each left out when no sample has what it needs.
fn breakdown(o: &mut String, report: &Report, colour: &dyn Fn(usize) -> &'static str) {
    let swatch = |i: usize, name: &str| {
        format!(
            "<td class=\"l\"><span class=\"swatch\" style=\"background:{}\"></span>{}</td>",
            colour(i),
            esc(name)
        )
    };
    if let Some(by) = &report.by_condition {
        let _ = write!(
            o,
            "<section><h2>By condition</h2><p class=\"note\">{}.</p><table id=\"condition\">\
             <tr><th class=\"l\">condition</th><th class=\"l\">method</th><th>EPE px</th><th>bad-2</th><th>D1</th>\
             <th>valid</th><th>streak EPE px</th><th>phantom-hole rate</th>\
             <th>failed samples</th></tr>",
            esc_code(report.breakdown["condition"].as_str().unwrap_or_default())
        );
        for c in by {
            let head = |rows: usize| {
                format!(
                    "<td rowspan=\"{rows}\" class=\"l\"><b>{}</b><br><span class=\"note\">{} \
                     sample{}</span></td>",
                    c.condition.name(),
                    c.samples,
                    if c.samples == 1 { "" } else { "s" }
                )
            };
            if c.summary.is_empty() {
                let _ = write!(
                    o,
                    "<tr>{}<td class=\"none\" colspan=\"8\" title=\"not available: no sample \
                     in this condition\">n/a</td></tr>",
                    head(1)
                );
                continue;
            }
            for (j, m) in c.summary.iter().enumerate() {
                let i = report
                    .summary
                    .iter()
                    .position(|s| s.method == m.method)
                    .unwrap_or(j);
                let e = &m.errors;
                let _ = write!(
                    o,
                    "<tr>{}{}{}{}{}<td>{}</td>{}{}{}</tr>",
                    if j == 0 {
                        head(c.summary.len())
                    } else {
                        String::new()
                    },
                    swatch(i, &m.method),
                    cell(&e.all, format!("{:.3}", e.all.mean_abs)),
                    cell(&e.all, pct(e.all.bad_2)),
                    cell(&e.all, pct(e.all.d1)),
                    pct(e.all.density),
                    region_cell(e.streak.as_ref(), |s| format!("{:.3}", s.mean_abs)),
                    phantom_cell(m),
                    failed_cell(m)
                );
            }
        }
        o.push_str("</table></section>\n");
    }
    let has = |list: fn(&Breakdown) -> &Option<Vec<BinErrors>>| {
        report.summary.iter().any(|m| list(&m.breakdown).is_some())
    };
    if has(|b| &b.streak_length) {
        let _ = write!(
            o,
            "<section><h2>By streak length</h2><p class=\"note\">{}.</p>\
             <table id=\"streak-length\"><tr><th rowspan=\"2\">method</th>",
            esc_code(
                report.breakdown["streak_length"]
                    .as_str()
                    .unwrap_or_default()
            )
        );
        for (k, b) in STREAK_LENGTH_BINS.iter().enumerate() {
            let range = if b.high.is_finite() {
                format!("{}-{} % of the height", 100.0 * b.low, 100.0 * b.high)
            } else {
                format!("&ge; {} % of the height", 100.0 * b.low)
            };
            let _ = write!(
                o,
                "<th colspan=\"3\">{}<br><span class=\"note\">{range}, {}</span></th>",
                b.name,
                bin_pixels(report, |b| &b.streak_length, k)
            );
        }
        o.push_str("</tr><tr>");
        for _ in STREAK_LENGTH_BINS {
            o.push_str("<th>EPE px</th><th>bad-2</th><th>&gt; 1 px below</th>");
        }
        o.push_str("</tr>");
        for (i, m) in report.summary.iter().enumerate() {
            let _ = write!(o, "<tr>{}", swatch(i, &m.method));
            for k in 0..STREAK_LENGTH_BINS.len() {
                let e = bin_of(&m.breakdown.streak_length, k);
                let _ = write!(
                    o,
                    "{}{}{}",
                    bin_cell(e, |e| format!("{:.3}", e.mean_abs)),
                    bin_cell(e, |e| pct(e.bad_2)),
                    bin_cell(e, |e| pct(e.below_1px))
                );
            }
            o.push_str("</tr>");
        }
        o.push_str("</table></section>\n");
    }
    if has(|b| &b.road_surface_by_distance) || has(|b| &b.off_road_by_distance) {
        let _ = write!(
            o,
            "<section><h2>By distance</h2><p class=\"note\">{}.</p>\
             <table id=\"distance\"><tr><th rowspan=\"2\">method</th>",
            esc_code(report.breakdown["distance"].as_str().unwrap_or_default())
        );
        for (k, b) in DISTANCE_BINS.iter().enumerate() {
            let _ = write!(
                o,
                "<th colspan=\"2\">{}<br><span class=\"note\">road {}, off-road {}</span></th>",
                esc(b.name),
                bin_pixels(report, |b| &b.road_surface_by_distance, k),
                bin_pixels(report, |b| &b.off_road_by_distance, k)
            );
        }
        o.push_str("</tr><tr>");
        for _ in DISTANCE_BINS {
            o.push_str("<th>road: phantom holes</th><th>off-road: bad-2</th>");
        }
        o.push_str("</tr>");
        for (i, m) in report.summary.iter().enumerate() {
            let _ = write!(o, "<tr>{}", swatch(i, &m.method));
            for k in 0..DISTANCE_BINS.len() {
                let _ = write!(
                    o,
                    "{}{}",
                    bin_cell(bin_of(&m.breakdown.road_surface_by_distance, k), |e| pct(
                        e.below_1px
                    )),
                    bin_cell(bin_of(&m.breakdown.off_road_by_distance, k), |e| pct(
                        e.bad_2
                    ))
                );
            }
            o.push_str("</tr>");
        }
        o.push_str("</table></section>\n");
    }
}

/// The page.
pub fn page(report: &Report, thumbs: &[SampleThumbs]) -> String {
    let colour = |i: usize| PALETTE[i % PALETTE.len()];
    let mut o = String::new();
    let _ = write!(
        o,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>streaks benchmark: {}</title><style>{CSS}</style></head><body>\n",
        esc(&report.input.dir)
    );
    let _ = write!(
        o,
        "<header><h1>Stereo methods against specular streaks</h1><p><code style=\"background:\
         #2c3a5c;color:#fff\">{}</code> &middot; {} &middot; {} samples{} &middot; {} methods</p>\
         <p>{}</p></header><main>",
        esc(&report.input.dir),
        esc(&format!("{:?}", report.input.kind).to_lowercase()),
        report.samples.len(),
        report
            .input
            .split
            .as_ref()
            .map(|s| format!(" (split {})", esc(s)))
            .unwrap_or_default(),
        report.methods.len(),
        esc(report.aggregation)
    );
    // Methods.
    o.push_str("<section><h2>Methods</h2><table class=\"methods\" id=\"methods\"><tr><th>method</th><th>kind</th><th>what it is</th><th>its time</th></tr>");
    for (i, m) in report.methods.iter().enumerate() {
        let _ = write!(
            o,
            "<tr><td><span class=\"swatch\" style=\"background:{}\"></span><b>{}</b></td>\
             <td>{}</td><td>{}</td><td>{}</td></tr>",
            colour(i),
            esc(&m.name),
            m.kind,
            esc_code(&m.description),
            esc(m.timing)
        );
    }
    o.push_str(
        "</table><p class=\"note\">Every method sees the same 8-bit left and right PNGs. A \
         disparity that is not finite or not positive counts as no value. EPE and bad-N are \
         over the pixels a method gives a value (its valid share is beside them), so a method \
         with few values (<code>lk</code>, which measures only along detected streaks) is \
         scored where it applies, not over the whole image; a dash means no values at all \
         (for <code>lk</code>: no streak detected); <i>n/a</i> means the samples have no mask \
         for that region (KITTI and Middlebury folders have no streak or road masks): not \
         available, not zero. Time is the method's wall time as its row above says, never the \
         scoring.</p></section>\n",
    );
    // Headline: phantom holes and time, and the charts.
    o.push_str("<section><h2>Summary</h2>");
    let failing: Vec<&MethodScore> = report.summary.iter().filter(|m| m.failed > 0).collect();
    if !failing.is_empty() {
        let each: Vec<String> = failing
            .iter()
            .map(|m| {
                if m.failed == m.samples {
                    format!("{} failed on every sample ({})", esc(&m.method), m.samples)
                } else {
                    format!(
                        "{} failed on {} of {} samples",
                        esc(&m.method),
                        m.failed,
                        m.samples
                    )
                }
            })
            .collect();
        let _ = write!(
            o,
            "<p class=\"fail\" id=\"failed\">{}. A method's figures cover the samples it \
             succeeded on (see <a href=\"#failures\">Failures</a>).</p>",
            each.join("; ")
        );
    }
    o.push_str("<table id=\"summary\"><tr><th>method</th><th>EPE px</th><th>bad-2</th><th>D1</th><th>valid</th><th>bad-2 filled</th><th>streak EPE px</th><th>phantom-hole rate</th><th>s / megapixel</th><th>failed samples</th></tr>");
    for (i, m) in report.summary.iter().enumerate() {
        let e = &m.errors;
        let _ = write!(
            o,
            "<tr><td><span class=\"swatch\" style=\"background:{}\"></span>{}</td>{}{}{}\
             <td>{}</td>{}{}{}{}{}</tr>",
            colour(i),
            esc(&m.method),
            cell(&e.all, format!("{:.3}", e.all.mean_abs)),
            cell(&e.all, pct(e.all.bad_2)),
            cell(&e.all, pct(e.all.d1)),
            pct(e.all.density),
            cell(&e.all, pct(e.all.bad_2_filled)),
            region_cell(e.streak.as_ref(), |s| format!("{:.3}", s.mean_abs)),
            phantom_cell(m),
            seconds_cell(m.seconds_per_megapixel),
            failed_cell(m)
        );
    }
    o.push_str("</table><p class=\"note\">The phantom-hole rate is the share of road pixels (streaks included) whose estimate is more than 1 px below the true disparity: stereo puts them beneath the road. Bad-2 filled is the share of all pixels with a truth that are more than 2 px off once the missing values are filled as KITTI's development kit fills a sparse map (each gap in a row takes the smaller of its two sides), so that sparse and dense methods are on one scale.</p><div class=\"grid\">");
    let bars = |f: &dyn Fn(&MethodScore) -> Option<f64>| -> Vec<Bar> {
        report
            .summary
            .iter()
            .enumerate()
            // A method with no values at all (it failed on every sample) has no bar.
            .filter(|(_, m)| m.errors.all.valid_pixels > 0)
            .filter_map(|(i, m)| f(m).map(|v| (m.method.clone(), colour(i).to_string(), v)))
            .collect()
    };
    let charts: [(&str, Vec<Bar>, bool); 6] = [
        (
            "Phantom-hole rate (road)",
            bars(&|m| m.phantom_hole_rate),
            true,
        ),
        (
            "bad-2, all pixels",
            bars(&|m| Some(m.errors.all.bad_2)),
            true,
        ),
        (
            "D1, non-occluded pixels",
            bars(&|m| m.errors.non_occluded.map(|e| e.d1)),
            true,
        ),
        (
            "EPE on streak pixels, px",
            bars(&|m| m.errors.streak.map(|e| e.mean_abs)),
            false,
        ),
        (
            "bad-2, off-road pixels",
            bars(&|m| m.errors.off_road.map(|e| e.bad_2)),
            true,
        ),
        (
            "Seconds per megapixel",
            bars(&|m| m.seconds_per_megapixel),
            false,
        ),
    ];
    for (title, b, is_share) in charts {
        if b.is_empty() {
            continue;
        }
        let fmt: &dyn Fn(f64) -> String = if is_share {
            &|v| pct(v)
        } else {
            &|v| format!("{v:.3}")
        };
        let _ = write!(o, "<div>{}</div>", bar_chart(title, &b, fmt));
    }
    o.push_str("</div></section>\n");
    // Region tables.
    o.push_str("<section><h2>By region</h2>");
    for (region, meaning) in REGIONS {
        if report
            .summary
            .iter()
            .all(|m| region_of(m, region).is_none())
        {
            continue;
        }
        let _ = write!(
            o,
            "<h3>{} <span style=\"font-weight:400\">&mdash; {}</span></h3><table \
             id=\"region-{}\"><tr><th>method</th><th>EPE px</th><th>bad-1</th><th>bad-2</th>\
             <th>bad-3</th><th>D1</th><th>valid</th><th>&gt; 1 px below</th><th>pixels</th></tr>",
            esc(region),
            esc(meaning),
            esc(region)
        );
        for (i, m) in report.summary.iter().enumerate() {
            if let Some(e) = region_of(m, region) {
                region_row(&mut o, &m.method, colour(i), e);
            }
        }
        o.push_str("</table>");
    }
    o.push_str("<p class=\"note\">D1 is KITTI 2015's: off by more than 3 px and by more than 5 % of the true disparity. A region is left out where no sample has its masks: the road regions without road masks (pair folders of scenes that flag no road, KITTI, Middlebury), the streak regions without streak masks (KITTI, Middlebury), the non-occluded pixels without an occlusion mask (KITTI's disp_noc_0, Middlebury's mask0nocc.png).</p></section>\n");
    breakdown(&mut o, report, &colour);
    // Per-sample table.
    o.push_str("<section><h2>Per sample</h2><table id=\"samples\"><tr><th>sample</th><th class=\"l\">method</th><th>EPE px</th><th>bad-2</th><th>streak EPE px</th><th>valid</th><th>phantom-hole rate</th><th>seconds</th><th>s / megapixel</th><th class=\"l\">status</th></tr>");
    for s in &report.samples {
        for (j, r) in s.results.iter().enumerate() {
            let first = if j == 0 {
                let plane = match &s.road_plane {
                    Some(c) if c.violated => format!(
                        "<br><span class=\"fail\" title=\"{}\">not on the road plane</span>",
                        esc(&c.message())
                    ),
                    _ => String::new(),
                };
                let conditions = s
                    .conditions
                    .as_ref()
                    .map(|cs| {
                        let names: Vec<&str> = cs.iter().map(|c| c.name()).collect();
                        format!("<br><span class=\"note\">{}</span>", names.join(", "))
                    })
                    .unwrap_or_default();
                format!(
                    "<td rowspan=\"{}\">{}<br><span class=\"note\">{}x{}</span>{conditions}\
                     {plane}</td>",
                    s.results.len(),
                    esc(&s.id),
                    s.width,
                    s.height
                )
            } else {
                String::new()
            };
            let e = &r.errors;
            let status = match &r.failure {
                Some(f) => format!(
                    "<td class=\"l fail\" title=\"{}\">failed: {}</td>",
                    esc(&f.reason),
                    esc(&kind_name(f.kind))
                ),
                None => "<td class=\"l\">ok</td>".to_string(),
            };
            let _ = write!(
                o,
                "<tr>{first}<td class=\"l\">{}</td>{}{}{}<td>{}</td>{}{}{}\
                 {status}</tr>",
                esc(&r.method),
                cell(&e.all, format!("{:.3}", e.all.mean_abs)),
                cell(&e.all, pct(e.all.bad_2)),
                region_cell(e.streak.as_ref(), |s| format!("{:.3}", s.mean_abs)),
                pct(e.all.density),
                phantom_cell(r),
                seconds_cell(r.seconds),
                seconds_cell(r.seconds_per_megapixel)
            );
        }
    }
    o.push_str("</table></section>\n");
    failures(&mut o, report);
    // Thumbnails.
    if !thumbs.is_empty() {
        let _ = write!(
            o,
            "<section><h2>Error maps</h2><p class=\"note\">Estimate minus truth per pixel \
             (first {} of {} samples).</p>{}",
            thumbs.len(),
            report.samples.len(),
            legend()
        );
        for t in thumbs {
            let _ = write!(
                o,
                "<div class=\"sample\"><h3>{}</h3><div class=\"thumbs\"><figure><img src=\"{}\" \
                 alt=\"left image of {}\"><figcaption>left image</figcaption></figure>",
                esc(&t.id),
                t.left,
                esc(&t.id)
            );
            for (m, uri) in &t.maps {
                let _ = write!(
                    o,
                    "<figure><img src=\"{uri}\" alt=\"{} error map of {}\"><figcaption>{}\
                     </figcaption></figure>",
                    esc(m),
                    esc(&t.id),
                    esc(m)
                );
            }
            o.push_str("</div></div>");
        }
        o.push_str("</section>\n");
    }
    let _ = write!(
        o,
        "<p class=\"note\">{} &middot; report.json beside this page has every figure.</p>\
         </main></body></html>",
        esc(report.format)
    );
    o.push('\n');
    o
}
