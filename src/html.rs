//! What the command's HTML pages share (`streaks benchmark`'s and `streaks dataset stats`'s):
//! escaping, the stylesheet, and the inline SVG charts, drawn here without scripts or
//! libraries so that a page reads offline.

use std::fmt::Write;

/// `s` escaped for HTML text and (quoted) attributes: nothing from a file becomes markup.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&#39;")
}

/// The pages' stylesheet (inline in each page).
pub const CSS: &str = r#"
:root { --ink: #1f2430; --muted: #5b6475; --line: #e3e6ec; --bg: #f6f7f9; --card: #fff; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif;
       color: var(--ink); background: var(--bg); }
header { background: #1f2a44; color: #fff; padding: 28px 40px 22px; }
header h1 { margin: 0 0 6px; font-size: 26px; font-weight: 650; letter-spacing: .2px; }
header p { margin: 2px 0; color: #c9d1e4; }
main { padding: 10px 40px 40px; max-width: 1400px; }
section { background: var(--card); border: 1px solid var(--line); border-radius: 10px;
          padding: 18px 22px; margin: 22px 0; box-shadow: 0 1px 2px rgba(0,0,0,.04); }
h2 { margin: 0 0 12px; font-size: 19px; }
h3 { margin: 18px 0 8px; font-size: 15px; color: var(--muted); font-weight: 600; }
table { border-collapse: collapse; margin: 4px 0 10px; font-variant-numeric: tabular-nums; }
th, td { padding: 5px 12px; text-align: right; border-bottom: 1px solid var(--line); }
th { font-weight: 600; color: var(--muted); font-size: 13px; background: #fafbfc; }
td:first-child, th:first-child, td.l, th.l { text-align: left; }
td:first-child { white-space: nowrap; }
tr:last-child td { border-bottom: none; }
.swatch { display: inline-block; width: 11px; height: 11px; border-radius: 2px;
          margin-right: 7px; vertical-align: -1px; }
.grid { display: flex; flex-wrap: wrap; gap: 18px 26px; }
.grid > div { flex: 0 1 auto; }
.note { color: var(--muted); font-size: 13.5px; max-width: 1000px; }
.methods td, .methods th { text-align: left; }
td.none { color: #9aa1ad; }
.sample { margin: 14px 0 22px; }
.sample h3 { margin: 0 0 6px; color: var(--ink); }
.thumbs { display: grid; grid-template-columns: repeat(auto-fill, minmax(220px, 1fr));
          gap: 10px; max-width: 1300px; }
figure { margin: 0; }
figure img { display: block; width: 100%; height: auto; border-radius: 4px;
             border: 1px solid var(--line); }
figcaption { font-size: 12.5px; color: var(--muted); margin-top: 3px; }
code { background: #eef1f5; padding: 1px 5px; border-radius: 4px; font-size: 13px; }
.fail { color: #b3261e; font-weight: 600; }
p.fail { background: #fdecea; border: 1px solid #f3b8b3; border-radius: 6px; padding: 8px 12px; }
pre { background: #f3f4f7; padding: 6px 8px; border-radius: 4px; font-size: 12px;
      max-height: 260px; overflow: auto; white-space: pre-wrap; text-align: left; }
td.reason { text-align: left; max-width: 700px; }
"#;

/// A bar of a chart: label, colour, value.
pub type Bar = (String, String, f64);

/// A horizontal bar chart (inline SVG) of `(label, colour, value)` bars, values formatted by
/// `fmt`.
pub fn bar_chart(title: &str, bars: &[Bar], fmt: &dyn Fn(f64) -> String) -> String {
    // Labels of 12.5 px text take about 7 px a character.
    let longest = bars.iter().map(|b| b.0.chars().count()).max().unwrap_or(0);
    let (label_w, bar_w, row_h) = ((7.0 * longest as f64 + 12.0).max(140.0), 300.0, 24.0);
    let max = bars.iter().map(|b| b.2).fold(0.0f64, f64::max);
    let scale = if max > 0.0 { bar_w / max } else { 0.0 };
    let h = 30.0 + row_h * bars.len() as f64;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         role=\"img\" aria-label=\"{t}\"><text x=\"0\" y=\"16\" font-size=\"13.5\" \
         font-weight=\"600\" fill=\"#1f2430\">{t}</text>",
        w = label_w + bar_w + 80.0,
        t = esc(title)
    );
    for (i, (label, colour, v)) in bars.iter().enumerate() {
        let y = 28.0 + row_h * i as f64;
        let len = (v * scale).max(if *v > 0.0 { 1.0 } else { 0.0 });
        let _ = write!(
            s,
            "<text x=\"{lx}\" y=\"{ty}\" font-size=\"12.5\" text-anchor=\"end\" \
             fill=\"#5b6475\">{l}</text><rect x=\"{label_w}\" y=\"{y}\" width=\"{len:.1}\" \
             height=\"{bh}\" rx=\"3\" fill=\"{colour}\"/><text x=\"{vx:.1}\" y=\"{ty}\" \
             font-size=\"12\" fill=\"#1f2430\">{v}</text>",
            lx = label_w - 8.0,
            ty = y + 13.0,
            l = esc(label),
            bh = row_h - 7.0,
            vx = label_w + len + 6.0,
            v = esc(&fmt(*v)),
        );
    }
    s.push_str("</svg>");
    s
}

/// A histogram (inline SVG) titled `title` of `counts` in equal bins spanning `lo..hi`, with
/// `band` (the range that was asked for, such as a config's `[min, max]`) shaded behind the
/// bars, and the axis ends labelled by `fmt`.
pub fn histogram(
    title: &str,
    counts: &[usize],
    lo: f64,
    hi: f64,
    band: Option<(f64, f64)>,
    fmt: &dyn Fn(f64) -> String,
) -> String {
    let (w, h, top, plot_h) = (330.0, 142.0, 24.0, 92.0);
    let (left, plot_w) = (8.0, 314.0);
    let max = counts.iter().copied().max().unwrap_or(0).max(1) as f64;
    let span = if hi > lo { hi - lo } else { 1.0 };
    let x_of = |v: f64| left + plot_w * ((v - lo) / span).clamp(0.0, 1.0);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" role=\"img\" \
         aria-label=\"{t}\"><text x=\"0\" y=\"15\" font-size=\"13\" font-weight=\"600\" \
         fill=\"#1f2430\">{t}</text>",
        t = esc(title)
    );
    if let Some((a, b)) = band {
        let (xa, xb) = (x_of(a), x_of(b));
        let _ = write!(
            s,
            "<rect x=\"{xa:.1}\" y=\"{top}\" width=\"{:.1}\" height=\"{plot_h}\" \
             fill=\"#dbe7f5\"><title>config range {} to {}</title></rect>",
            (xb - xa).max(1.0),
            esc(&fmt(a)),
            esc(&fmt(b))
        );
    }
    let bin_w = plot_w / counts.len().max(1) as f64;
    for (i, &c) in counts.iter().enumerate() {
        if c == 0 {
            continue;
        }
        let bh = (plot_h * c as f64 / max).max(1.0);
        let _ = write!(
            s,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bh:.1}\" fill=\"#4e79a7\">\
             <title>{c}</title></rect>",
            left + bin_w * i as f64 + 0.5,
            top + plot_h - bh,
            (bin_w - 1.0).max(0.5)
        );
    }
    let base = top + plot_h;
    let _ = write!(
        s,
        "<line x1=\"{left}\" y1=\"{base}\" x2=\"{}\" y2=\"{base}\" stroke=\"#5b6475\"/>\
         <text x=\"{left}\" y=\"{ty}\" font-size=\"11.5\" fill=\"#5b6475\">{}</text>\
         <text x=\"{}\" y=\"{ty}\" font-size=\"11.5\" text-anchor=\"end\" fill=\"#5b6475\">{}</text>\
         <text x=\"{}\" y=\"{ty}\" font-size=\"11.5\" text-anchor=\"middle\" fill=\"#9aa1ad\">tallest bin {}</text>",
        left + plot_w,
        esc(&fmt(lo)),
        left + plot_w,
        esc(&fmt(hi)),
        left + plot_w / 2.0,
        max,
        ty = base + 15.0
    );
    s.push_str("</svg>");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Markup in text and attributes is escaped, quotes of both kinds included.
    #[test]
    fn escaping_leaves_no_markup() {
        assert_eq!(
            esc("<img src=x onerror='a'> & \"b\""),
            "&lt;img src=x onerror=&#39;a&#39;&gt; &amp; &quot;b&quot;"
        );
    }

    /// A histogram draws one bar per non-empty bin, the tallest the plot's height, and the
    /// band where it was asked for; its title is escaped.
    #[test]
    fn histogram_bars_follow_the_counts() {
        let svg = histogram("<t>", &[2, 0, 1, 0], 0.0, 4.0, Some((1.0, 3.0)), &|v| {
            v.to_string()
        });
        assert!(svg.contains("&lt;t&gt;") && !svg.contains("<t>"));
        // Bars: bin 0 full height (92 px), bin 2 half; the band from x = 8 + 314/4.
        assert!(svg.contains("height=\"92.0\" fill=\"#4e79a7\""), "{svg}");
        assert!(svg.contains("height=\"46.0\" fill=\"#4e79a7\""), "{svg}");
        assert_eq!(svg.matches("fill=\"#4e79a7\"").count(), 2);
        assert!(
            svg.contains("<rect x=\"86.5\" y=\"24\" width=\"157.0\""),
            "{svg}"
        );
    }
}
