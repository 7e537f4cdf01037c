//! `streaks benchmark DIR --method NAME... [--method-cmd NAME=TEMPLATE]... [--predictions
//! NAME=DIR]... -o OUT`: stereo methods scored against the ground truth of a dataset, of
//! `streaks stereo` pair folders, or of a KITTI 2015 or Middlebury 2014 folder, by region
//! (streak, road, off-road, non-occluded) and broken down by condition, streak length and
//! distance ([`streaks_analysis::benchmark::breakdown`]), with `OUT/report.json` ([`report`]) and a
//! self-contained `OUT/index.html` ([`html`]).
//!
//! - [`input`]: the samples of DIR;
//! - [`method`]: the built-in methods (`sgm`, `sgm-streaks`, `lk`, the analysis crate's
//!   [`streaks_analysis::benchmark::method`]), external commands (per sample or one batch)
//!   and prediction folders;
//! - [`command`]: an external command's template and process, run without a shell;
//! - [`maps`]: disparity maps on disk (PFM or KITTI PNG by extension);
//! - [`report`]: the report's top level (its parts are
//!   [`streaks_analysis::benchmark::report`]'s);
//! - [`html`]: the page.
//!
//! Scoring and pooling are [`streaks_analysis::benchmark`]. Batch commands run first, once
//! each; then every method gives its map of every sample (a progress bar over samples x
//! methods). A method that fails on a sample (see [`report::FailureKind`])
//! is recorded as failed there with its reason and output tails, left out of its summary
//! ([`report::FAILURE_SCORING`]), and the run goes on; at the end both outputs are written
//! atomically, the failures listed, and the command exits non-zero unless
//! `--allow-failures`. Bad input (no samples, an unreadable ground truth or mask) still stops
//! the run before anything is written.

pub mod command;
pub mod html;
pub mod input;
pub mod maps;
pub mod method;
pub mod report;

use anyhow::{bail, Context, Result};
use method::Method;
use report::{Input, MethodInfo, MethodScore, Report, SampleReport};
use std::path::PathBuf;
use std::time::Duration;
use streaks_analysis::benchmark::breakdown::{score_breakdown, SampleBins};
use streaks_analysis::benchmark::{error_map, score_regions, BAD_THRESHOLD_PX};
use streaks_analysis::road_plane::RoadPlaneCheck;
use streaks_dataset::files::SampleDir;
use streaks_image::pfm::read_pfm;
use streaks_image::{write_bytes_atomically, GrayImage};
use streaks_stereo::rig::Eye;

/// Score stereo methods against the ground truth of a dataset, pair folders, a KITTI 2015 or a
/// Middlebury 2014 folder.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A dataset (`streaks dataset generate`), a `streaks stereo` pair folder, a folder of
    /// pair folders, a KITTI 2015 folder (`training/image_2`, `image_3`, `disp_occ_0`), or a
    /// Middlebury 2014 scene folder (`im0.png`, `im1.png`, `disp0GT.pfm`) or folder of them.
    pub dir: PathBuf,
    /// Methods to run: built-in `sgm`, `sgm-streaks`, `lk`, or the name of a --method-cmd or
    /// --predictions (every --method-cmd and --predictions runs, named here or not).
    #[arg(long = "method", value_name = "NAME", num_args = 1..)]
    pub methods: Vec<String>,
    /// An external method: NAME=TEMPLATE, a program and its arguments (split into words like a
    /// shell would, but run without one) in which `{left}`, `{right}` and `{out}` are replaced
    /// by the absolute paths of the left and right PNGs and of the PFM disparity map it must
    /// write (inf, NaN or <= 0: no value); the paths are also in $STREAKS_LEFT,
    /// $STREAKS_RIGHT and $STREAKS_OUT. A TEMPLATE with `{list}` runs once for all samples:
    /// `{list}` ($STREAKS_LIST) is a file of `left<TAB>right<TAB>out` lines. NAME:png makes
    /// the outputs KITTI uint16 PNGs.
    #[arg(long = "method-cmd", value_name = "NAME=TEMPLATE")]
    pub method_cmds: Vec<String>,
    /// Maps made beforehand: NAME=DIR, DIR holding `<sample id>.pfm` or `<sample id>.png`
    /// (KITTI uint16) per sample; a missing or bad map fails that sample.
    #[arg(long = "predictions", value_name = "NAME=DIR")]
    pub predictions: Vec<String>,
    /// Time limit of an external method on one sample, seconds: past it the command and its
    /// whole process group are killed and the sample is recorded as failed.
    #[arg(long, value_name = "SECONDS", default_value = "600", value_parser = parse_timeout)]
    pub method_timeout: Duration,
    /// Exit 0 even when a method failed on some samples (the report records them either way).
    #[arg(long)]
    pub allow_failures: bool,
    /// Only this split of a dataset (train, val, test).
    #[arg(long)]
    pub split: Option<String>,
    /// Output folder: report.json and index.html.
    #[arg(short, long)]
    pub output: PathBuf,
    /// How many samples get thumbnails on the page (the first ones).
    #[arg(long, default_value_t = 8)]
    pub thumbnails: usize,
}

/// `--method-timeout`: positive seconds, fractions allowed.
fn parse_timeout(s: &str) -> std::result::Result<Duration, String> {
    let secs: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number of seconds"))?;
    if secs.is_nan() || secs <= 0.0 {
        return Err(format!("{s} s: the time limit must be more than 0 s"));
    }
    Duration::try_from_secs_f64(secs).map_err(|_| format!("{s} s is too long a time limit"))
}

/// The methods of the arguments, in order: `--method` names, then the other `--method-cmd`s
/// and `--predictions`.
fn methods(args: &Args) -> Result<Vec<Method>> {
    let commands = args
        .method_cmds
        .iter()
        .map(|s| Method::command(s))
        .chain(args.predictions.iter().map(|s| Method::predictions(s)))
        .collect::<Result<Vec<_>>>()?;
    for (i, c) in commands.iter().enumerate() {
        if commands[..i].iter().any(|o| o.name() == c.name()) {
            bail!("the method name {} is given twice", c.name());
        }
    }
    let mut out: Vec<Method> = Vec::new();
    for name in &args.methods {
        let m = Method::built_in(name)
            .or_else(|| commands.iter().find(|c| c.name() == name).cloned())
            .with_context(|| {
                format!(
                    "unknown method {name:?}: the built-in methods are {}; an external one \
                     needs --method-cmd {name}=TEMPLATE, maps made beforehand --predictions \
                     {name}=DIR",
                    streaks_analysis::benchmark::method::BUILT_INS
                        .map(|(n, _)| n)
                        .join(", ")
                )
            })?;
        if out.iter().any(|o| o.name() == m.name()) {
            bail!("method {name} is named twice");
        }
        out.push(m);
    }
    for c in commands {
        if !args.methods.iter().any(|n| n == c.name()) {
            out.push(c);
        }
    }
    if out.is_empty() {
        bail!(
            "no method: give --method sgm (or sgm-streaks, lk), --method-cmd NAME=TEMPLATE or \
             --predictions NAME=DIR"
        );
    }
    Ok(out)
}

/// The road-plane check of `sample` with its `road` mask ([`RoadPlaneCheck::from_depth`]),
/// when it has a ground-truth depth (`None` without one).
fn road_plane(sample: &input::Sample, road: &GrayImage) -> Result<Option<RoadPlaneCheck>> {
    let files = SampleDir::open(&sample.dir)?;
    let path = files.depth(Eye::Left);
    if !path.is_file() {
        return Ok(None);
    }
    let depth = read_pfm(&path).with_context(|| format!("reading the depth {}", path.display()))?;
    let (rig, _) = files.rig()?;
    Ok(RoadPlaneCheck::from_depth(&depth, road, &rig))
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let methods = methods(&args)?;
    if args.output.is_file() {
        bail!(
            "the output {} is a file, not a folder",
            args.output.display()
        );
    }
    let (kind, samples) = input::samples(&args.dir, args.split.as_deref())?;
    // Commands write their maps here; it goes away with the run.
    let work = tempfile::Builder::new()
        .prefix("streaks-benchmark-")
        .tempdir()
        .context("cannot create a temporary folder")?;
    let mut batches = Vec::with_capacity(methods.len());
    for m in &methods {
        if matches!(m, Method::Command { template, .. } if template.is_batch()) {
            eprintln!(
                "running the batch command {} on all {} samples",
                m.name(),
                samples.len()
            );
        }
        batches.push(m.run_batch(&samples, work.path(), args.method_timeout)?);
    }
    let bar = crate::cli::progress_bar((samples.len() * methods.len()) as u64);
    let mut sample_reports = Vec::new();
    let mut thumbs = Vec::new();
    for (k, sample) in samples.iter().enumerate() {
        let truth = sample.read_truth()?;
        let size = (truth.width, truth.height);
        let masks = sample.masks(size)?;
        let road = masks.road.as_ref();
        let bins = SampleBins::new(size, &masks.as_masks(), sample.read_depth(size)?.as_ref())
            .with_context(|| format!("sample {}", sample.id))?;
        let conditions = sample
            .conditions()
            .with_context(|| format!("the conditions of sample {}", sample.id))?;
        let megapixels = (size.0 * size.1) as f64 / 1e6;
        let mut results = Vec::new();
        let mut maps = Vec::new();
        for (m, batch) in methods.iter().zip(&batches) {
            let what = || format!("method {} on sample {}", m.name(), sample.id);
            let outcome = m.run(
                sample,
                k,
                size,
                work.path(),
                args.method_timeout,
                batch.as_ref(),
            );
            let (disp, failure) = match outcome.result {
                Ok(disp) => (disp, None),
                Err(f) => {
                    if outcome.announce {
                        bar.suspend(|| eprintln!("{}", failure_line(m.name(), &sample.id, &f)));
                    }
                    (GrayImage::new(size.0, size.1, f32::INFINITY)?, Some(f))
                }
            };
            let errors = score_regions(&disp, &truth, &masks.as_masks()).with_context(what)?;
            let breakdown =
                score_breakdown(&disp, &truth, &masks.as_masks(), &bins).with_context(what)?;
            if k < args.thumbnails {
                maps.push((m.name().to_string(), error_map(&disp, &truth)?));
            }
            results.push(
                MethodScore::new(m.name(), errors, outcome.seconds, megapixels, failure)
                    .with_breakdown(breakdown),
            );
            bar.inc(1);
        }
        if k < args.thumbnails {
            let left = streaks_image::input::load_image(&sample.left)
                .with_context(|| format!("reading {}", sample.left.display()))?
                .to_rgb8();
            thumbs.push(html::SampleThumbs::new(&sample.id, &left, &maps)?);
        }
        let road_plane = match road {
            Some(road) => road_plane(sample, road)?,
            None => None,
        };
        if let Some(c) = road_plane.filter(|c| c.violated) {
            bar.suspend(|| eprintln!("warning: sample {}: {}", sample.id, c.message()));
        }
        sample_reports.push(SampleReport {
            id: sample.id.clone(),
            dir: sample.dir.display().to_string(),
            width: size.0,
            height: size.1,
            streak_mask: masks.streaks.is_some(),
            road_mask: road.is_some(),
            occlusion_mask: masks.non_occluded.is_some(),
            conditions,
            road_plane,
            results,
        });
    }
    bar.finish_and_clear();
    let summary = report::summary(methods.iter().map(|m| m.name()), &sample_reports)
        .context("pooling the samples")?;
    let by_condition = report::by_condition(methods.iter().map(|m| m.name()), &sample_reports);
    let report = Report {
        format: report::FORMAT,
        input: Input {
            dir: args.dir.display().to_string(),
            kind,
            split: args.split.clone(),
        },
        aggregation: report::AGGREGATION,
        bad_threshold_px: BAD_THRESHOLD_PX,
        regions: report::REGIONS
            .iter()
            .map(|(k, v)| (k.to_string(), serde_json::Value::from(*v)))
            .collect(),
        methods: methods
            .iter()
            .map(|m| MethodInfo {
                name: m.name().to_string(),
                kind: m.kind(),
                description: m.description(),
                timing: m.timing(),
            })
            .collect(),
        breakdown: report::breakdown_definitions(),
        summary,
        by_condition,
        samples: sample_reports,
        failure_scoring: report::FAILURE_SCORING,
        unavailable: report::UNAVAILABLE,
    };
    let page = html::page(&report, &thumbs);
    let mut json = serde_json::to_string_pretty(&report)?;
    json.push('\n');
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create the folder {}", args.output.display()))?;
    let (json_path, html_path) = (
        args.output.join("report.json"),
        args.output.join("index.html"),
    );
    write_bytes_atomically(&json_path, json.as_bytes())?;
    write_bytes_atomically(&html_path, page.as_bytes())?;
    eprint!("{}", summary_table(&report));
    eprintln!(
        "{} samples x {} methods; wrote {} and {}",
        report.samples.len(),
        report.methods.len(),
        json_path.display(),
        html_path.display()
    );
    let failed: usize = report.summary.iter().map(|m| m.failed).sum();
    if failed > 0 {
        let per_method: Vec<String> = report
            .summary
            .iter()
            .filter(|m| m.failed > 0)
            .map(|m| format!("{} on {} of {} samples", m.method, m.failed, m.samples))
            .collect();
        let message = format!(
            "{failed} method runs failed ({}); {} and {} record each failure with its reason",
            per_method.join(", "),
            json_path.display(),
            html_path.display()
        );
        if args.allow_failures {
            eprintln!("warning: {message}");
        } else {
            bail!("{message} (--allow-failures exits 0 all the same)");
        }
    }
    Ok(())
}

/// One line (and the stderr tail's last lines) saying that `method` failed on `sample`.
fn failure_line(method: &str, sample: &str, f: &report::Failure) -> String {
    let mut s = format!(
        "warning: method {method} failed on sample {sample:?}: {}",
        f.reason
    );
    let lines: Vec<&str> = f.stderr_tail.lines().collect();
    if !lines.is_empty() {
        s.push_str("\n  its stderr ended:");
        for l in &lines[lines.len().saturating_sub(12)..] {
            s.push_str("\n    ");
            s.push_str(l);
        }
    }
    s
}

/// The summary as a text table (EPE, bad-2, D1, valid share over all pixels; phantom holes;
/// seconds per megapixel).
fn summary_table(report: &Report) -> String {
    let mut s = format!(
        "{:<16} {:>8} {:>8} {:>8} {:>8} {:>10} {:>8} {:>8}\n",
        "method", "EPE", "bad-2", "D1", "valid", "streak EPE", "phantom", "s/MP"
    );
    let mut notes = String::new();
    let pct = |v: f64| format!("{:.1}%", 100.0 * v);
    for m in &report.summary {
        let e = &m.errors;
        // A figure over the pixels with a value: `-` when there are none.
        let valued = |d: &streaks_analysis::sgm::DisparityErrors, text: String| {
            if d.valid_pixels == 0 {
                "-".to_string()
            } else {
                text
            }
        };
        s.push_str(&format!(
            "{:<16} {:>8} {:>8} {:>8} {:>8} {:>10} {:>8} {:>8}\n",
            m.method,
            valued(&e.all, format!("{:.3}", e.all.mean_abs)),
            valued(&e.all, pct(e.all.bad_2)),
            valued(&e.all, pct(e.all.d1)),
            pct(e.all.density),
            match &e.streak {
                Some(streak) => valued(streak, format!("{:.3}", streak.mean_abs)),
                None => "n/a".to_string(),
            },
            match (m.phantom_hole_rate, e.road_surface) {
                (Some(v), _) => pct(v),
                (None, None) => "n/a".into(),
                (None, Some(_)) => "-".into(),
            },
            m.seconds_per_megapixel
                .map(|v| format!("{v:.2}"))
                .unwrap_or_else(|| "-".into())
        ));
        if m.failed > 0 {
            notes.push_str(&format!(
                "{} failed on {} of {} samples{}\n",
                m.method,
                m.failed,
                m.samples,
                if m.failed == m.samples {
                    ": every sample, it has no score"
                } else {
                    " (its figures cover the others)"
                }
            ));
        }
    }
    s.push_str(&notes);
    s
}
