//! `streaks dataset stats DIR [-o HTML] [--thumbnails N] [--contact-sheet N]`: one
//! self-contained HTML page (default `DIR/stats.html`) that shows what a dataset holds, and a
//! contact sheet of it (`DIR/stats/contact_sheet.png`).
//!
//! The page has, per config table (street, lamps, cars, weather, rig, ...), a histogram of
//! every numeric parameter the generator drew (the `params` of each sample's `meta.json`,
//! flattened into named leaves, [`flatten`]) with the config's range shaded behind it and its
//! config entry beside it, and a bar chart of counts of every categorical one (lamp type, rain
//! class, sensor, ...); the samples per split and the frames per street; thumbnails of the
//! samples (small PNGs under `DIR/stats/thumbs/`, each linked to its folder, subsampled evenly
//! beyond `--thumbnails`); and the samples that are missing or could not be read, by name.
//! Nothing is known of the parameters in advance: a parameter the generator adds shows up on
//! the page by itself. Every string from a file is escaped.
//!
//! The contact sheet is `--contact-sheet` samples (12 by default) in a grid four wide, each
//! with a caption, chosen from as many streets as possible, spread evenly over them
//! ([`contact_sheet_choice`]).

use crate::cli::progress_bar;
use crate::html::{bar_chart, esc, histogram, CSS};
use anyhow::{bail, Context, Result};
use image::RgbImage;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use streaks_dataset::layout::{sample_id, DatasetInfo, Layout};
use streaks_dataset::SampleDir;
use streaks_image::input::{load_image, read_text, MAX_TEXT_BYTES};
use streaks_image::png::png_bytes;
use streaks_image::write_bytes_atomically;
use streaks_stereo::rig::Eye;

/// Write an HTML page of histograms of a dataset's parameters, with thumbnails, and a contact
/// sheet.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The dataset folder (written by `streaks dataset generate`).
    pub dir: PathBuf,
    /// The page to write [default: DIR/stats.html].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Most thumbnails on the page; a larger dataset shows this many, evenly spaced.
    #[arg(long, default_value_t = 240)]
    pub thumbnails: usize,
    /// Samples on the contact sheet (DIR/stats/contact_sheet.png), four per row; 0 writes none.
    #[arg(long, default_value_t = 12)]
    pub contact_sheet: usize,
}

/// Width of a thumbnail on the page, pixels.
const THUMB_WIDTH: u32 = 240;
/// Width of a tile of the contact sheet, pixels.
const SHEET_TILE_WIDTH: u32 = 480;
/// Height of a caption strip of the contact sheet, pixels.
const SHEET_CAPTION: u32 = 26;
/// Tiles per row of the contact sheet.
const SHEET_COLUMNS: usize = 4;
/// Bins of a histogram.
const BINS: usize = 24;
/// Most bars of a categorical chart; the rest are counted as one "others" bar.
const MAX_CATEGORIES: usize = 12;
/// Most streets listed in the frames-per-street table.
const MAX_STREET_ROWS: usize = 60;
/// Units a parameter's name may add to its config key (`intensity_w_sr` is `intensity`).
const UNIT_SUFFIXES: [&str; 7] = ["_w_sr", "_cd_m2", "_mm_h", "_m", "_s", "_deg", "_k"];

/// A value found at a leaf of a sample's parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Leaf {
    /// A number.
    Num(f64),
    /// A string or a boolean: a category.
    Cat(String),
    /// A non-empty array of numbers: a vector (a colour, a position) when every sample's has
    /// the same short length, else a list (its length and its values pooled).
    Numbers(Vec<f64>),
}

/// The named leaves of a JSON value: objects are walked (`a.b`), numbers, strings and
/// booleans are leaves, an array of numbers is one [`Leaf::Numbers`], and any other array
/// gives its length (`a (count)`) and its elements' leaves pooled under `a[]`. `null` gives
/// nothing.
pub fn flatten(prefix: &str, value: &Value, out: &mut Vec<(String, Leaf)>) {
    let join = |k: &str| {
        if prefix.is_empty() {
            k.to_owned()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match value {
        Value::Null => {}
        Value::Bool(b) => out.push((prefix.to_owned(), Leaf::Cat(b.to_string()))),
        Value::Number(n) => {
            if let Some(x) = n.as_f64() {
                out.push((prefix.to_owned(), Leaf::Num(x)));
            }
        }
        Value::String(s) => out.push((prefix.to_owned(), Leaf::Cat(s.clone()))),
        Value::Array(items) => {
            let numbers: Option<Vec<f64>> = items.iter().map(Value::as_f64).collect();
            match numbers {
                Some(v) if !v.is_empty() => out.push((prefix.to_owned(), Leaf::Numbers(v))),
                _ => {
                    out.push((count_name(prefix), Leaf::Num(items.len() as f64)));
                    let inner = format!("{prefix}[]");
                    for item in items {
                        flatten(&inner, item, out);
                    }
                }
            }
        }
        Value::Object(map) => {
            for (k, v) in map {
                flatten(&join(k), v, out);
            }
        }
    }
}

/// The name of a list's length.
fn count_name(list: &str) -> String {
    format!("{list} (count)")
}

/// Every value drawn of one named parameter, over the samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Param {
    /// The numbers.
    pub nums: Vec<f64>,
    /// The categories and their counts.
    pub cats: BTreeMap<String, usize>,
}

/// The parameters of all samples by name: [`flatten`]'s leaves gathered, numbers arrays
/// resolved into vector components (`a[0]`, `a[1]`, ... when every sample's has the same
/// length, at most 4, and the array is never empty) or lists (`a (count)` and the values
/// pooled under `a[]`).
pub fn gather(samples: &[Vec<(String, Leaf)>]) -> BTreeMap<String, Param> {
    let mut lengths: BTreeMap<&str, BTreeSet<usize>> = BTreeMap::new();
    let mut counted: BTreeSet<String> = BTreeSet::new();
    for leaves in samples {
        for (name, leaf) in leaves {
            match leaf {
                Leaf::Numbers(v) => {
                    lengths.entry(name).or_default().insert(v.len());
                }
                Leaf::Num(_) => {
                    if let Some(list) = name.strip_suffix(" (count)") {
                        counted.insert(list.to_owned());
                    }
                }
                Leaf::Cat(_) => {}
            }
        }
    }
    let is_vector = |name: &str| {
        let l = &lengths[name];
        l.len() == 1 && l.iter().all(|&n| n <= 4) && !counted.contains(name)
    };
    let mut params: BTreeMap<String, Param> = BTreeMap::new();
    for leaves in samples {
        for (name, leaf) in leaves {
            match leaf {
                Leaf::Num(x) => params.entry(name.clone()).or_default().nums.push(*x),
                Leaf::Cat(c) => {
                    *params
                        .entry(name.clone())
                        .or_default()
                        .cats
                        .entry(c.clone())
                        .or_default() += 1
                }
                Leaf::Numbers(v) if is_vector(name) => {
                    for (i, x) in v.iter().enumerate() {
                        params
                            .entry(format!("{name}[{i}]"))
                            .or_default()
                            .nums
                            .push(*x);
                    }
                }
                Leaf::Numbers(v) => {
                    params
                        .entry(count_name(name))
                        .or_default()
                        .nums
                        .push(v.len() as f64);
                    params
                        .entry(format!("{name}[]"))
                        .or_default()
                        .nums
                        .extend(v);
                }
            }
        }
    }
    params
}

/// The first segment of a parameter's name, without list or index marks.
fn segments(name: &str) -> Vec<&str> {
    name.split('.')
        .map(|s| {
            let s = s.strip_suffix(" (count)").unwrap_or(s);
            s.split('[').next().unwrap_or(s)
        })
        .collect()
}

/// The config table a parameter belongs to: the table of its first segment's name, or the
/// table whose name or one of whose keys starts it (`exposure_ev` is `[exposure]`'s,
/// `headlight_type` is `[cars]`'s `headlight_types`), else `other`.
pub fn group_of(name: &str, config: &Value) -> String {
    let first = segments(name)[0];
    let Some(tables) = config.as_object() else {
        return "other".into();
    };
    if tables.get(first).is_some_and(Value::is_object) {
        return first.to_owned();
    }
    for table in tables.keys() {
        if first.starts_with(&format!("{table}_")) {
            return table.clone();
        }
    }
    for (table, t) in tables {
        if t.as_object()
            .is_some_and(|keys| keys.keys().any(|k| leaf_matches(first, k)))
        {
            return table.clone();
        }
    }
    "other".into()
}

/// Whether the parameter leaf `leaf` is drawn from the config key `key`: the same name, the
/// name with a unit ([`UNIT_SUFFIXES`]), the plural (`types` for `type`), or a class
/// (`rain_class` from `rain`).
fn leaf_matches(leaf: &str, key: &str) -> bool {
    leaf == key
        || UNIT_SUFFIXES
            .iter()
            .any(|u| leaf.strip_suffix(u) == Some(key))
        || key.strip_suffix('s') == Some(leaf)
        || leaf.strip_suffix("_class") == Some(key)
}

/// The config entry a parameter was drawn from, if one is found: the config's value at the
/// parameter's path in its table, the last segment matched by [`leaf_matches`].
pub fn config_entry<'a>(name: &str, group: &str, config: &'a Value) -> Option<&'a Value> {
    let mut segs = segments(name);
    let mut node = config.get(group)?;
    if segs[0] == group {
        segs.remove(0);
    } else if let Some(rest) = segs[0].strip_prefix(&format!("{group}_")) {
        segs[0] = rest;
    }
    let (last, path) = segs.split_last()?;
    for s in path {
        node = node.get(*s)?;
    }
    let keys = node.as_object()?;
    keys.get(*last).or_else(|| {
        keys.iter()
            .find(|(k, _)| leaf_matches(last, k))
            .map(|(_, v)| v)
    })
}

/// A `[min, max]` range of numbers.
fn as_range(v: &Value) -> Option<(f64, f64)> {
    match v.as_array()?.as_slice() {
        [a, b] => Some((a.as_f64()?, b.as_f64()?)),
        _ => None,
    }
}

/// Compact JSON of a config entry, at most 160 characters.
fn short_json(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 160 {
        format!("{}…", s.chars().take(160).collect::<String>())
    } else {
        s
    }
}

/// `n` equal bins over `lo..=hi` (the last bin closed) and each value's count; all in the
/// first bin when `hi <= lo`.
pub fn bin_counts(values: &[f64], lo: f64, hi: f64, n: usize) -> Vec<usize> {
    let mut counts = vec![0; n.max(1)];
    let last = counts.len() - 1;
    for &v in values.iter().filter(|v| v.is_finite()) {
        let i = if hi > lo {
            (((v - lo) / (hi - lo)) * counts.len() as f64).floor()
        } else {
            0.0
        };
        counts[(i.max(0.0) as usize).min(last)] += 1;
    }
    counts
}

/// A number for a person: a few significant digits.
fn num(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_owned()
    } else {
        format!("{v:.3e}")
    }
}

/// One sample as the page shows it.
struct Sample {
    id: String,
    split: String,
    street: Option<u64>,
    caption: String,
    leaves: Vec<(String, Leaf)>,
    /// The bytes of its folder's files and of its files in the dataset's views.
    bytes: u64,
}

/// A string at `path` of a JSON value, or `–`.
fn text_at(v: &Value, path: &[&str]) -> String {
    let mut node = v;
    for p in path {
        match node.get(*p) {
            Some(n) => node = n,
            None => return "–".into(),
        }
    }
    match node {
        Value::String(s) => s.clone(),
        Value::Null => "–".into(),
        other => other.to_string(),
    }
}

/// Reads one sample's `meta.json`: its id, split, street, caption and flattened parameters
/// (the generator's `params` and the rendered `stats`), and the bytes its files take (those of
/// its folder and of the views of `layout`; sizes only, nothing is opened).
fn read_sample(layout: &Layout, id: &str, dir: &SampleDir) -> Result<Sample> {
    let path = dir.meta();
    let text = read_text(&path, MAX_TEXT_BYTES)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let meta: Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not valid JSON", path.display()))?;
    if !meta.is_object() {
        bail!("{} is not a JSON object", path.display());
    }
    let params = meta.get("params").unwrap_or(&Value::Null);
    let mut leaves = Vec::new();
    flatten("", params, &mut leaves);
    if let Some(stats) = meta.get("stats") {
        flatten("rendered", stats, &mut leaves);
    }
    let split = text_at(&meta, &["split"]);
    let weather = text_at(params, &["weather", "rain_class"]);
    let lamp = text_at(params, &["lamps", "type"]);
    let street = meta.get("street").and_then(Value::as_u64);
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir.path())
        .map(|entries| entries.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    if let (Ok(index), Some(street)) = (id.parse::<u64>(), street) {
        let all = Default::default();
        files.extend(
            layout
                .view_files(index, &split, street, &all)
                .into_iter()
                .map(|(_, p)| p),
        );
    }
    let bytes = files
        .iter()
        .filter_map(|p| std::fs::symlink_metadata(p).ok())
        .filter(|m| m.is_file())
        .map(|m| m.len())
        .sum();
    Ok(Sample {
        id: id.to_owned(),
        caption: format!("{weather} · {lamp} · {split}"),
        split,
        street,
        leaves,
        bytes,
    })
}

/// The samples of the contact sheet: `n` of them, at most one per street until every street
/// has one, the streets spread evenly over the dataset's; then second frames, and so on.
/// `streets` is each sample's street (samples without one count as their own street), in
/// sample order; the result is indices into it, in sample order.
pub fn contact_sheet_choice(streets: &[Option<u64>], n: usize) -> Vec<usize> {
    let mut by_street: BTreeMap<(u64, usize), Vec<usize>> = BTreeMap::new();
    for (i, s) in streets.iter().enumerate() {
        let key = match s {
            Some(s) => (*s, 0),
            None => (u64::MAX, i),
        };
        by_street.entry(key).or_default().push(i);
    }
    let groups: Vec<Vec<usize>> = by_street.into_values().collect();
    let mut chosen = Vec::new();
    let mut round = 0;
    while chosen.len() < n.min(streets.len()) {
        let open: Vec<&Vec<usize>> = groups.iter().filter(|g| g.len() > round).collect();
        let want = (n - chosen.len()).min(open.len());
        // `want` of the `open` streets, evenly spaced.
        for k in 0..want {
            chosen.push(open[k * open.len() / want][round]);
        }
        round += 1;
    }
    chosen.sort_unstable();
    chosen
}

/// `n` of `0..total`, evenly spaced (all of them when `n >= total`).
fn evenly(total: usize, n: usize) -> Vec<usize> {
    if n >= total {
        return (0..total).collect();
    }
    (0..n).map(|k| k * total / n).collect()
}

/// A reference from the page in `page_dir` to `target`: relative when `target` is inside the
/// page's folder, else a `file://` URL; percent-encoded where needed.
fn href(page_dir: &Path, target: &Path) -> String {
    let encode = |s: &str| {
        let mut o = String::new();
        for b in s.bytes() {
            if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
                o.push(b as char);
            } else {
                let _ = write!(o, "%{b:02X}");
            }
        }
        o
    };
    match target.strip_prefix(page_dir) {
        Ok(rel) => encode(&rel.to_string_lossy()),
        Err(_) => format!("file://{}", encode(&target.to_string_lossy())),
    }
}

/// Runs `streaks dataset stats`.
pub fn run(args: Args) -> Result<()> {
    let root = args
        .dir
        .canonicalize()
        .with_context(|| format!("cannot open the dataset folder {}", args.dir.display()))?;
    let layout = Layout::new(&root);
    let (config, count) = match DatasetInfo::load(&layout.dataset_json()) {
        Ok(info) => (info.config, Some(info.count)),
        Err(e) => {
            eprintln!("warning: {e}; the page shows no config ranges");
            (Value::Null, None)
        }
    };
    let ids = layout.sample_ids(None)?;
    let mut problems: Vec<(String, String)> = Vec::new();
    if let Some(count) = count {
        let present: BTreeSet<&str> = ids.iter().map(String::as_str).collect();
        for i in 0..count {
            let id = sample_id(i);
            if !present.contains(id.as_str()) {
                problems.push((id, "missing: no sample folder".into()));
            }
        }
    }
    let bar = progress_bar(ids.len() as u64);
    let mut samples = Vec::new();
    for id in &ids {
        match read_sample(&layout, id, &layout.sample_by_id(id)) {
            Ok(s) => samples.push(s),
            Err(e) => {
                bar.suspend(|| eprintln!("warning: sample {id} skipped: {e:#}"));
                problems.push((id.clone(), format!("{e:#}")));
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    if samples.is_empty() {
        bail!("no sample of {} could be read", root.display());
    }
    let out_dir = root.join("stats");
    let thumbs_dir = out_dir.join("thumbs");
    std::fs::create_dir_all(&thumbs_dir)
        .with_context(|| format!("cannot create {}", thumbs_dir.display()))?;
    let page_path = args
        .output
        .clone()
        .unwrap_or_else(|| root.join("stats.html"));
    let page_parent = page_path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(page_parent)
        .with_context(|| format!("cannot create the folder {}", page_parent.display()))?;
    let page_dir = page_parent
        .canonicalize()
        .with_context(|| format!("cannot open the folder of {}", page_path.display()))?;

    // Thumbnails.
    let shown = evenly(samples.len(), args.thumbnails);
    let bar = progress_bar(shown.len() as u64);
    let mut thumbs = Vec::new();
    for &i in &shown {
        let s = &samples[i];
        let dir = layout.sample_by_id(&s.id);
        let file = thumbs_dir.join(format!("{}.png", s.id));
        let made = load_image(&dir.png(Eye::Left))
            .map_err(anyhow::Error::from)
            .and_then(|img| {
                let small = scaled(&img.to_rgb8(), THUMB_WIDTH, false);
                write_bytes_atomically(&file, &png_bytes(&small)?)?;
                Ok(())
            });
        match made {
            Ok(()) => thumbs.push((i, Some(href(&page_dir, &file)))),
            Err(e) => {
                let reason = format!("no thumbnail: {e:#}");
                bar.suspend(|| eprintln!("warning: sample {}: {reason}", s.id));
                problems.push((s.id.clone(), reason));
                thumbs.push((i, None));
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();

    // Contact sheet.
    let mut sheet_note = String::new();
    if args.contact_sheet > 0 {
        let streets: Vec<Option<u64>> = samples.iter().map(|s| s.street).collect();
        let chosen = contact_sheet_choice(&streets, args.contact_sheet);
        let path = out_dir.join("contact_sheet.png");
        let tiles: Vec<(String, RgbImage)> = chosen
            .iter()
            .filter_map(|&i| {
                let s = &samples[i];
                let img = load_image(&layout.sample_by_id(&s.id).png(Eye::Left)).ok()?;
                Some((format!("{}  {}", s.id, s.caption), img.to_rgb8()))
            })
            .collect();
        if !tiles.is_empty() {
            let sheet = contact_sheet(&tiles)?;
            write_bytes_atomically(&path, &png_bytes(&sheet)?)?;
            eprintln!("wrote {}", path.display());
            sheet_note = format!(
                "<p><a href=\"{}\">Contact sheet</a> of {} samples from {} streets.</p>",
                esc(&href(&page_dir, &path)),
                tiles.len(),
                chosen
                    .iter()
                    .map(|&i| samples[i].street)
                    .collect::<BTreeSet<_>>()
                    .len()
            );
        }
    }

    let page = page(
        &root,
        &page_dir,
        &config,
        &samples,
        &thumbs,
        &problems,
        &sheet_note,
    );
    write_bytes_atomically(&page_path, page.as_bytes())?;
    eprintln!(
        "wrote {} ({} samples, {} thumbnails, {} skipped or missing)",
        page_path.display(),
        samples.len(),
        thumbs.len(),
        problems.len()
    );
    Ok(())
}

/// `img` scaled to `width` pixels wide (kept when narrower, unless `enlarge`).
fn scaled(img: &RgbImage, width: u32, enlarge: bool) -> RgbImage {
    let (w, h) = img.dimensions();
    if w == width || (w < width && !enlarge) {
        return img.clone();
    }
    let th = ((h as f64 * width as f64 / w as f64).round() as u32).max(1);
    image::imageops::resize(img, width, th, image::imageops::FilterType::Triangle)
}

/// The contact sheet: the tiles scaled to [`SHEET_TILE_WIDTH`] (small ones enlarged), [`SHEET_COLUMNS`] per row,
/// each with its caption on a dark strip below it.
fn contact_sheet(tiles: &[(String, RgbImage)]) -> Result<RgbImage> {
    use plotters::prelude::*;
    streaks_stereo::font::register_sans_serif()?;
    let tw = SHEET_TILE_WIDTH;
    let th = tiles
        .iter()
        .map(|(_, img)| scaled(img, tw, true).height().max(1))
        .max()
        .unwrap_or(1);
    let cols = SHEET_COLUMNS.min(tiles.len()) as u32;
    let rows = tiles.len().div_ceil(SHEET_COLUMNS) as u32;
    let gap = 4;
    let cell_h = th + SHEET_CAPTION;
    let (w, h) = (
        cols * tw + (cols + 1) * gap,
        rows * cell_h + (rows + 1) * gap,
    );
    let mut sheet = RgbImage::from_pixel(w, h, image::Rgb([24, 26, 32]));
    for (k, (_, img)) in tiles.iter().enumerate() {
        let (c, r) = ((k % SHEET_COLUMNS) as u32, (k / SHEET_COLUMNS) as u32);
        let small = scaled(img, tw, true);
        let x = gap + c * (tw + gap) + (tw - small.width()) / 2;
        let y = gap + r * (cell_h + gap);
        image::imageops::replace(&mut sheet, &small, x as i64, y as i64);
    }
    let mut buf = sheet.into_raw();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let style = ("sans-serif", 15)
            .into_font()
            .color(&RGBColor(225, 228, 235));
        for (k, (caption, _)) in tiles.iter().enumerate() {
            let (c, r) = ((k % SHEET_COLUMNS) as u32, (k / SHEET_COLUMNS) as u32);
            let x = gap + c * (tw + gap) + 6;
            let y = gap + r * (cell_h + gap) + th + 5;
            root.draw(&Text::new(caption.clone(), (x as i32, y as i32), &style))
                .map_err(|e| anyhow::anyhow!("drawing the contact sheet's captions: {e}"))?;
        }
        root.present()
            .map_err(|e| anyhow::anyhow!("drawing the contact sheet: {e}"))?;
    }
    RgbImage::from_raw(w, h, buf).context("the contact sheet's buffer has the wrong size")
}

/// The page.
fn page(
    root: &Path,
    page_dir: &Path,
    config: &Value,
    samples: &[Sample],
    thumbs: &[(usize, Option<String>)],
    problems: &[(String, String)],
    sheet_note: &str,
) -> String {
    let mut o = String::new();
    let _ = write!(
        o,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>streaks dataset stats: {d}</title><style>{CSS}{STATS_CSS}</style></head><body>\n\
         <header><h1>Dataset statistics</h1><p>{d}</p><p>{n} samples read, {p} missing or \
         skipped; {b:.0} bytes per sample (its folder and its KITTI and SceneFlow files)</p>\
         </header><main>\n",
        d = esc(&root.display().to_string()),
        n = samples.len(),
        p = problems.len(),
        b = samples.iter().map(|s| s.bytes as f64).sum::<f64>() / samples.len().max(1) as f64
    );

    // Splits and streets.
    let mut splits: BTreeMap<&str, usize> = BTreeMap::new();
    let mut streets: BTreeMap<Option<u64>, (usize, BTreeSet<&str>)> = BTreeMap::new();
    for s in samples {
        *splits.entry(&s.split).or_default() += 1;
        let e = streets.entry(s.street).or_default();
        e.0 += 1;
        e.1.insert(&s.split);
    }
    o.push_str("<section><h2>Splits and streets</h2><div class=\"grid\"><div>");
    let bars: Vec<_> = splits
        .iter()
        .map(|(k, v)| (k.to_string(), "#4e79a7".to_string(), *v as f64))
        .collect();
    o.push_str(&bar_chart("Samples per split", &bars, &|v| format!("{v}")));
    o.push_str("</div><div>");
    let mut frames: BTreeMap<usize, usize> = BTreeMap::new();
    for (n, _) in streets.values() {
        *frames.entry(*n).or_default() += 1;
    }
    let bars: Vec<_> = frames
        .iter()
        .map(|(k, v)| (format!("{k} frames"), "#59a14f".to_string(), *v as f64))
        .collect();
    o.push_str(&bar_chart(
        &format!("Streets by frames ({} streets)", streets.len()),
        &bars,
        &|v| format!("{v}"),
    ));
    o.push_str(
        "</div><div><table><tr><th>street</th><th>frames</th><th class=\"l\">split</th></tr>",
    );
    for (street, (n, sp)) in streets.iter().take(MAX_STREET_ROWS) {
        let name = street.map_or("–".to_string(), |s| s.to_string());
        let sp: Vec<&str> = sp.iter().copied().collect();
        let _ = write!(
            o,
            "<tr><td>{name}</td><td>{n}</td><td class=\"l\">{}</td></tr>",
            esc(&sp.join(", "))
        );
    }
    o.push_str("</table>");
    if streets.len() > MAX_STREET_ROWS {
        let _ = write!(
            o,
            "<p class=\"note\">The first {MAX_STREET_ROWS} of {} streets.</p>",
            streets.len()
        );
    }
    o.push_str("</div></div></section>\n");

    // Problems.
    if !problems.is_empty() {
        let _ = write!(
            o,
            "<section><h2>Missing or skipped ({})</h2><table><tr><th>sample</th>\
             <th class=\"l\">reason</th></tr>",
            problems.len()
        );
        for (id, reason) in problems {
            let _ = write!(
                o,
                "<tr><td>{}</td><td class=\"reason\">{}</td></tr>",
                esc(id),
                esc(reason)
            );
        }
        o.push_str("</table></section>\n");
    }

    // Parameters, by config table.
    let all: Vec<Vec<(String, Leaf)>> = samples.iter().map(|s| s.leaves.clone()).collect();
    let params = gather(&all);
    let mut groups: BTreeMap<String, Vec<(&String, &Param)>> = BTreeMap::new();
    for (name, p) in &params {
        let group = if name.starts_with("rendered.") {
            "~rendered".to_string()
        } else {
            group_of(name, config)
        };
        groups.entry(group).or_default().push((name, p));
    }
    o.push_str(
        "<section><h2>Parameters</h2><p class=\"note\">Every parameter the generator drew, \
         from the samples' <code>meta.json</code>, grouped by config table. A histogram's \
         shaded band is the config's range; the config entry is under it. Lists (cars, \
         lamps, blocks) give their length per sample (<em>count</em>) and their elements' \
         values pooled (<em>[]</em>).</p>",
    );
    for (group, list) in &groups {
        let title = match group.as_str() {
            "~rendered" => "rendered statistics (meta.json stats)".to_string(),
            g => format!("[{g}]"),
        };
        let _ = write!(o, "<h3>{}</h3><div class=\"grid\">", esc(&title));
        let mut constants = Vec::new();
        for (name, p) in list {
            let entry = config_entry(name, group, config);
            let entry_html = entry
                .map(|e| {
                    format!(
                        "<div class=\"cfg\">config: <code>{}</code></div>",
                        esc(&short_json(e))
                    )
                })
                .unwrap_or_default();
            if !p.nums.is_empty() {
                let finite: Vec<f64> = p.nums.iter().copied().filter(|v| v.is_finite()).collect();
                let (lo, hi) = finite
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                        (a.min(v), b.max(v))
                    });
                if finite.is_empty() || lo == hi {
                    constants.push((name, num(lo), p.nums.len(), entry));
                } else {
                    let band = entry.and_then(as_range);
                    let (x0, x1) = band.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi)));
                    let counts = bin_counts(&finite, x0, x1, BINS);
                    let mean = finite.iter().sum::<f64>() / finite.len() as f64;
                    let _ = write!(
                        o,
                        "<div class=\"param\">{}<div class=\"cap\">n {} · drawn {} to {} · mean {}</div>{}</div>",
                        histogram(name, &counts, x0, x1, band, &num),
                        finite.len(),
                        num(lo),
                        num(hi),
                        num(mean),
                        entry_html
                    );
                }
            }
            if !p.cats.is_empty() {
                if p.cats.len() == 1 {
                    let (k, n) = p.cats.iter().next().expect("one category");
                    constants.push((name, k.clone(), *n, entry));
                    continue;
                }
                let mut sorted: Vec<(&String, &usize)> = p.cats.iter().collect();
                sorted.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
                let mut bars: Vec<_> = sorted
                    .iter()
                    .take(MAX_CATEGORIES)
                    .map(|(k, v)| (k.to_string(), "#f28e2b".to_string(), **v as f64))
                    .collect();
                if sorted.len() > MAX_CATEGORIES {
                    let rest: usize = sorted[MAX_CATEGORIES..].iter().map(|(_, v)| **v).sum();
                    bars.push((
                        format!("{} others", sorted.len() - MAX_CATEGORIES),
                        "#bab0ac".to_string(),
                        rest as f64,
                    ));
                }
                let _ = write!(
                    o,
                    "<div class=\"param cat\">{}{}</div>",
                    bar_chart(name, &bars, &|v| format!("{v}")),
                    entry_html
                );
            }
        }
        o.push_str("</div>");
        if !constants.is_empty() {
            o.push_str(
                "<table class=\"consts\"><tr><th class=\"l\">the same in every sample</th>\
                 <th class=\"l\">value</th><th>samples</th><th class=\"l\">config</th></tr>",
            );
            for (name, value, n, entry) in constants {
                let _ = write!(
                    o,
                    "<tr><td>{}</td><td class=\"l\">{}</td><td>{n}</td><td class=\"l\">{}</td></tr>",
                    esc(name),
                    esc(&value),
                    entry.map_or(String::new(), |e| format!("<code>{}</code>", esc(&short_json(e))))
                );
            }
            o.push_str("</table>");
        }
    }
    o.push_str("</section>\n");

    // Thumbnails.
    let _ = write!(o, "<section><h2>Samples</h2>{sheet_note}");
    if thumbs.len() < samples.len() {
        let _ = write!(
            o,
            "<p class=\"note\">{} of {} samples shown, evenly spaced (every {:.1}th); \
             <code>--thumbnails</code> shows more.</p>",
            thumbs.len(),
            samples.len(),
            samples.len() as f64 / thumbs.len().max(1) as f64
        );
    }
    o.push_str("<div class=\"thumbs\">");
    for (i, src) in thumbs {
        let s = &samples[*i];
        let folder = href(page_dir, &root.join("samples").join(&s.id));
        let img = match src {
            Some(src) => format!(
                "<img src=\"{}\" alt=\"{}\" loading=\"lazy\">",
                esc(src),
                esc(&s.id)
            ),
            None => "<div class=\"noimg\">no image</div>".to_string(),
        };
        let _ = write!(
            o,
            "<figure><a href=\"{}/\">{img}</a><figcaption><b>{}</b> street {}<br>{}</figcaption></figure>",
            esc(&folder),
            esc(&s.id),
            s.street.map_or("–".to_string(), |v| v.to_string()),
            esc(&s.caption)
        );
    }
    o.push_str("</div></section>\n</main></body></html>\n");
    o
}

/// The stats page's additions to [`CSS`].
const STATS_CSS: &str = r#"
.param { width: 340px; }
.param.cat { width: auto; max-width: 720px; }
.cap, .cfg { font-size: 12px; color: var(--muted); overflow-wrap: anywhere; }
.cfg code { font-size: 11.5px; }
table.consts td, table.consts th { font-size: 13px; padding: 3px 10px; }
.thumbs { grid-template-columns: repeat(auto-fill, minmax(180px, 1fr)); }
.noimg { height: 100px; background: #eee; color: #999; display: flex; align-items: center;
         justify-content: center; }
"#;

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Objects are walked, arrays of objects give a count and pooled leaves, nulls nothing.
    #[test]
    fn flatten_names_every_leaf() {
        let v = json!({"a": {"b": 1.5, "c": "x", "d": null, "e": true},
                       "cars": [{"kind": "k1", "x": 1}, {"kind": "k2", "x": 2}],
                       "color": [0.1, 0.2, 0.3], "empty": []});
        let mut out = Vec::new();
        flatten("", &v, &mut out);
        assert_eq!(
            out,
            vec![
                ("a.b".into(), Leaf::Num(1.5)),
                ("a.c".into(), Leaf::Cat("x".into())),
                ("a.e".into(), Leaf::Cat("true".into())),
                ("cars (count)".into(), Leaf::Num(2.0)),
                ("cars[].kind".into(), Leaf::Cat("k1".into())),
                ("cars[].x".into(), Leaf::Num(1.0)),
                ("cars[].kind".into(), Leaf::Cat("k2".into())),
                ("cars[].x".into(), Leaf::Num(2.0)),
                ("color".into(), Leaf::Numbers(vec![0.1, 0.2, 0.3])),
                ("empty (count)".into(), Leaf::Num(0.0)),
            ]
        );
    }

    /// A numbers array of one short length everywhere is a vector; one whose length varies
    /// (or is sometimes empty) is a list.
    #[test]
    fn vectors_and_lists_are_told_apart() {
        let a = vec![
            ("c".to_string(), Leaf::Numbers(vec![1.0, 2.0])),
            ("z".to_string(), Leaf::Numbers(vec![5.0])),
        ];
        let b = vec![
            ("c".to_string(), Leaf::Numbers(vec![3.0, 4.0])),
            ("z (count)".to_string(), Leaf::Num(0.0)),
        ];
        let p = gather(&[a, b]);
        assert_eq!(p["c[0]"].nums, vec![1.0, 3.0]);
        assert_eq!(p["c[1]"].nums, vec![2.0, 4.0]);
        assert_eq!(p["z (count)"].nums, vec![1.0, 0.0]);
        assert_eq!(p["z[]"].nums, vec![5.0]);
        assert!(!p.contains_key("z[0]"));
    }

    /// Parameters find their config table and entry by name, unit suffix, plural or class.
    #[test]
    fn parameters_find_their_config() {
        let config = json!({
            "lamps": {"height": [5.0, 9.0], "types": {"a": 1.0}, "intensity": [1.5, 5.0]},
            "cars": {"headlight_intensity": [10.0, 40.0], "headlight_types": {"h": 1.0}},
            "exposure": {"ev": [4.5, 6.5]},
            "weather": {"rain": [], "fog": {"sigma_t": [0.0, 0.1]}},
        });
        let cases = [
            ("lamps.height", "lamps", Some(json!([5.0, 9.0]))),
            ("lamps.type", "lamps", Some(json!({"a": 1.0}))),
            ("lamps.intensity_w_sr", "lamps", Some(json!([1.5, 5.0]))),
            ("lamps.intensity_cd", "lamps", None),
            (
                "headlight_intensity_w_sr",
                "cars",
                Some(json!([10.0, 40.0])),
            ),
            ("headlight_type", "cars", Some(json!({"h": 1.0}))),
            ("exposure_ev", "exposure", Some(json!([4.5, 6.5]))),
            ("weather.rain_class", "weather", Some(json!([]))),
            ("weather.fog.sigma_t", "weather", Some(json!([0.0, 0.1]))),
            ("mystery", "other", None),
        ];
        for (name, group, entry) in cases {
            assert_eq!(group_of(name, &config), group, "{name}");
            assert_eq!(config_entry(name, group, &config).cloned(), entry, "{name}");
        }
    }

    /// Values fall in their bins; the top edge is in the last bin.
    #[test]
    fn bins_count_each_value_once() {
        assert_eq!(
            bin_counts(&[0.0, 0.49, 0.5, 1.0, f64::NAN], 0.0, 1.0, 2),
            vec![2, 2]
        );
        assert_eq!(bin_counts(&[3.0, 3.0], 3.0, 3.0, 4), vec![2, 0, 0, 0]);
    }

    /// The contact sheet takes one frame per street, streets spread evenly, before any
    /// second frame.
    #[test]
    fn contact_sheet_spreads_over_streets() {
        // 6 streets of 4 frames each.
        let streets: Vec<Option<u64>> = (0..24).map(|i| Some(i / 4)).collect();
        assert_eq!(contact_sheet_choice(&streets, 3), vec![0, 8, 16]);
        let twelve = contact_sheet_choice(&streets, 12);
        assert_eq!(twelve.len(), 12);
        for s in 0..6u64 {
            assert_eq!(twelve.iter().filter(|&&i| streets[i] == Some(s)).count(), 2);
        }
        assert_eq!(contact_sheet_choice(&streets[..2], 12), vec![0, 1]);
        // Samples without a street are each their own.
        assert_eq!(contact_sheet_choice(&[None, None, None], 2), vec![0, 1]);
    }

    /// Links inside the page's folder are relative, others file URLs; both percent-encoded.
    #[test]
    fn links_are_encoded() {
        let dir = Path::new("/d");
        assert_eq!(href(dir, Path::new("/d/stats/a b.png")), "stats/a%20b.png");
        assert_eq!(href(dir, Path::new("/e/\"x\"")), "file:///e/%22x%22");
    }
}
