//! The methods `streaks benchmark` runs: the built-ins ([`BuiltIn`], the analysis crate's),
//! external commands (a process per sample, or one batch process for all samples) and
//! prediction folders (maps made beforehand).

use super::command::{self, Ended, Paths, Template, ENV_LIST};
use super::input::Sample;
use super::maps::{read_method_map, MapFormat};
use super::report::{Failure, FailureKind};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use streaks_analysis::benchmark::method::BuiltIn;
use streaks_image::GrayImage;

/// One method.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Method {
    /// A built-in method.
    BuiltIn(BuiltIn),
    /// An external command: a template with `{left}`, `{right}` and `{out}`, or `{list}`.
    Command {
        /// The method's name.
        name: String,
        /// The template, split into words.
        template: Template,
        /// The format of the maps it writes (the extension of `{out}`).
        format: MapFormat,
    },
    /// Maps made beforehand: `DIR/<sample id>.pfm` or `.png`.
    Predictions {
        /// The method's name.
        name: String,
        /// The folder of maps.
        dir: PathBuf,
    },
}

/// What a method gave on one sample.
pub struct Outcome {
    /// The disparity of the left view, or why the method failed on the sample.
    pub result: std::result::Result<GrayImage, Failure>,
    /// The method's wall time on the sample, seconds (`None`: not timed, a prediction).
    pub seconds: Option<f64>,
    /// Whether a failure is to be printed: a batch run's failure is every sample's, printed
    /// once.
    pub announce: bool,
}

/// One run of a batch command over all samples ([`Method::run_batch`]).
pub struct Batch {
    /// Why the run failed, if it did: then it failed on every sample.
    failure: Option<Failure>,
    /// Its wall time, seconds.
    seconds: f64,
    /// The pixels of all samples, over which the time is shared.
    pixels: f64,
}

/// `NAME`, checked: letters, digits, `-`, `_`, `.`, and not a built-in's. `flag` and `spec`
/// are for the error.
fn checked_name<'a>(flag: &str, spec: &str, name: &'a str) -> Result<&'a str> {
    let name = name.trim();
    let ok = |c: char| c.is_ascii_alphanumeric() || "-_.".contains(c);
    if name.is_empty() || !name.chars().all(ok) {
        bail!("{flag} {spec:?}: the name must be letters, digits, '-', '_' or '.', got {name:?}");
    }
    if Method::built_in(name).is_some() {
        bail!("{flag} {name}: {name} is a built-in method; choose another name");
    }
    Ok(name)
}

/// The file a command writes for sample `index`: named by the index, the checked method name
/// and the format, in the run's private folder, so nothing of the input's folder names
/// reaches it.
fn out_path(work: &Path, index: usize, name: &str, format: MapFormat) -> PathBuf {
    let abs = std::path::absolute(work).unwrap_or_else(|_| work.to_path_buf());
    abs.join(format!("{index:06}-{name}.{}", format.extension()))
}

/// A failure without output tails.
fn failure(kind: FailureKind, reason: String) -> Failure {
    Failure {
        kind,
        reason,
        stderr_tail: String::new(),
        stdout_tail: String::new(),
    }
}

/// How much of a command's stderr a failure keeps: its last lines and characters.
const FAILURE_TAIL: (usize, usize) = (40, 4000);

/// Why a finished command failed (`None`: it exited with status 0), with its output tails;
/// `limit` says what time limit it ran under.
fn run_failure(output: &command::Output, limit: &str) -> Option<Failure> {
    let (lines, chars) = FAILURE_TAIL;
    let failed = |kind, mut reason: String| {
        if output.output_left_open {
            reason
                .push_str("; a process it started left its process group and held its output open");
        }
        Failure {
            kind,
            reason,
            stderr_tail: output.stderr.text(lines, chars),
            stdout_tail: output.stdout.text(lines, chars),
        }
    };
    let status = match output.ended {
        Ended::TimedOut => {
            return Some(failed(
                FailureKind::Timeout,
                format!("ran longer than {limit}: its process group was killed"),
            ))
        }
        Ended::Status(s) => s,
    };
    if status.success() {
        return None;
    }
    use std::os::unix::process::ExitStatusExt;
    Some(match status.signal() {
        Some(sig) => failed(FailureKind::Signal, format!("killed by signal {sig}")),
        None => failed(
            FailureKind::Exit,
            format!("exited with status {}", status.code().unwrap_or(-1)),
        ),
    })
}

/// Removes a leftover of an earlier run at `out`, so it is never taken for this run's output.
fn remove_old(out: &Path) -> std::result::Result<(), Failure> {
    match std::fs::remove_file(out) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(failure(
            FailureKind::Error,
            format!("cannot remove the old output {}: {e}", out.display()),
        )),
        _ => Ok(()),
    }
}

/// Starts `argv` ([`command::run`]), or the failure to start it.
fn start(
    argv: &[std::ffi::OsString],
    env: &[(&str, &std::ffi::OsStr)],
    timeout: Duration,
) -> std::result::Result<command::Output, Failure> {
    command::run(argv, env, timeout).map_err(|e| {
        let program = argv
            .first()
            .map(|p| p.to_string_lossy())
            .unwrap_or_default();
        failure(FailureKind::Spawn, format!("cannot run {program:?}: {e}"))
    })
}

/// A command's map `out` for a sample of `size`, after the command exited with status 0.
fn read_output(out: &Path, size: (usize, usize)) -> std::result::Result<GrayImage, Failure> {
    read_method_map(out, size, false).map_err(|(kind, reason)| match kind {
        FailureKind::Missing => failure(
            FailureKind::NoOutput,
            format!("exited with status 0 but wrote no {}", out.display()),
        ),
        kind => failure(kind, format!("its output: {reason}")),
    })
}

impl Method {
    /// The built-in method `name`.
    pub fn built_in(name: &str) -> Option<Method> {
        BuiltIn::from_name(name).map(Method::BuiltIn)
    }

    /// `--method-cmd NAME[:png]=TEMPLATE`, checked: `:png` makes `{out}` (and the list's
    /// outputs) KITTI uint16 PNGs, else they are PFMs.
    pub fn command(spec: &str) -> Result<Method> {
        let flag = "--method-cmd";
        let Some((name, template)) = spec.split_once('=') else {
            bail!("{flag} {spec:?}: expected NAME=TEMPLATE");
        };
        let (name, format) = match name.trim().split_once(':') {
            None => (name, MapFormat::Pfm),
            Some((name, ext)) => match MapFormat::ALL.into_iter().find(|f| f.extension() == ext) {
                Some(f) => (name, f),
                None => bail!(
                    "{flag} {spec:?}: {ext:?} is not an output format; NAME:png writes KITTI \
                     uint16 PNGs, NAME or NAME:pfm PFMs"
                ),
            },
        };
        let name = checked_name(flag, spec, name)?;
        Ok(Method::Command {
            name: name.to_string(),
            template: Template::parse(name, template)?,
            format,
        })
    }

    /// `--predictions NAME=DIR`, checked: DIR must be a folder.
    pub fn predictions(spec: &str) -> Result<Method> {
        let flag = "--predictions";
        let Some((name, dir)) = spec.split_once('=') else {
            bail!("{flag} {spec:?}: expected NAME=DIR");
        };
        let name = checked_name(flag, spec, name)?;
        let dir = PathBuf::from(dir);
        if !dir.is_dir() {
            bail!("{flag} {name}: {} is not a folder", dir.display());
        }
        Ok(Method::Predictions {
            name: name.to_string(),
            dir,
        })
    }

    /// The method's name.
    pub fn name(&self) -> &str {
        match self {
            Method::BuiltIn(m) => m.name(),
            Method::Command { name, .. } | Method::Predictions { name, .. } => name,
        }
    }

    /// Its kind, as the report names it.
    pub fn kind(&self) -> &'static str {
        match self {
            Method::BuiltIn(_) => "built-in",
            Method::Command { template, .. } if template.is_batch() => "batch-command",
            Method::Command { .. } => "command",
            Method::Predictions { .. } => "predictions",
        }
    }

    /// What its time covers, as the report states it.
    pub fn timing(&self) -> &'static str {
        match self {
            Method::BuiltIn(_) => {
                "in-process wall time per sample: reading the two PNGs and \
                estimating"
            }
            Method::Command { template, .. } if template.is_batch() => {
                "the one process's wall \
                time over all samples, shared among them in proportion to their pixels"
            }
            Method::Command { .. } => "wall time of the whole process per sample",
            Method::Predictions { .. } => "not timed: the maps were made beforehand",
        }
    }

    /// What the method is, for the report.
    pub fn description(&self) -> String {
        match self {
            Method::Command {
                template, format, ..
            } => {
                let what = if template.is_batch() {
                    "external batch command"
                } else {
                    "external command"
                };
                match format {
                    MapFormat::Pfm => format!("{what}: `{}`", template.text()),
                    MapFormat::KittiPng => {
                        format!("{what} writing KITTI PNGs: `{}`", template.text())
                    }
                }
            }
            Method::Predictions { dir, .. } => {
                format!("predictions made beforehand, read from `{}`", dir.display())
            }
            Method::BuiltIn(m) => m.description().to_string(),
        }
    }

    /// For a batch command, runs it once over `samples` (with `work` the run's private folder
    /// and `timeout` the limit per sample: the run gets it times the samples); `None` for any
    /// other method. An error (a path the list file cannot hold, an unreadable image size)
    /// stops the benchmark; the command's own failure is every sample's.
    pub fn run_batch(
        &self,
        samples: &[Sample],
        work: &Path,
        timeout: Duration,
    ) -> Result<Option<Batch>> {
        let Method::Command {
            name,
            template,
            format,
        } = self
        else {
            return Ok(None);
        };
        if !template.is_batch() {
            return Ok(None);
        }
        let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let mut pixels = 0.0;
        let mut files = Vec::with_capacity(samples.len());
        for (k, s) in samples.iter().enumerate() {
            let (w, h) = image::image_dimensions(&s.left)
                .with_context(|| format!("reading the size of {}", s.left.display()))?;
            pixels += f64::from(w) * f64::from(h);
            let out = out_path(work, k, name, *format);
            if let Err(f) = remove_old(&out) {
                bail!("{}", f.reason);
            }
            files.push((abs(&s.left), abs(&s.right), out));
        }
        let paths: Vec<Paths> = files
            .iter()
            .map(|(left, right, out)| Paths { left, right, out })
            .collect();
        let list = abs(work).join(format!("{name}-list.tsv"));
        command::write_list(&list, &paths).with_context(|| format!("--method-cmd {name}"))?;
        let limit = timeout.saturating_mul(samples.len().max(1) as u32);
        let (failure, seconds) = match start(
            &template.batch_argv(&list),
            &[(ENV_LIST, list.as_os_str())],
            limit,
        ) {
            Err(f) => (Some(f), 0.0),
            Ok(output) => {
                let what = format!(
                    "{} s (--method-timeout {} s times {} samples)",
                    limit.as_secs_f64(),
                    timeout.as_secs_f64(),
                    samples.len()
                );
                (run_failure(&output, &what), output.seconds)
            }
        };
        let failure = failure.map(|mut f| {
            f.reason
                .push_str(&format!(" (its one run for all {} samples)", samples.len()));
            f
        });
        Ok(Some(Batch {
            failure,
            seconds,
            pixels,
        }))
    }

    /// Runs the method on `sample` (the `index`-th; `size` its ground truth's), with `work` the
    /// run's private folder for a command's output, `timeout` a command's time limit and
    /// `batch` this method's [`Method::run_batch`]. Gives the disparity of the left view (no
    /// value: `inf`; a disparity that is not finite or not positive is no value, whatever the
    /// method), or why the method failed on the sample, and its time ([`Method::timing`]).
    pub fn run(
        &self,
        sample: &Sample,
        index: usize,
        size: (usize, usize),
        work: &Path,
        timeout: Duration,
        batch: Option<&Batch>,
    ) -> Outcome {
        let outcome = |result, seconds| Outcome {
            result,
            seconds,
            announce: true,
        };
        match (self, batch) {
            (Method::Command { name, format, .. }, Some(b)) => {
                let share = (size.0 * size.1) as f64 / b.pixels.max(1.0);
                let seconds = Some(b.seconds * share);
                match &b.failure {
                    Some(f) => Outcome {
                        result: Err(f.clone()),
                        seconds,
                        announce: index == 0,
                    },
                    None => outcome(
                        read_output(&out_path(work, index, name, *format), size),
                        seconds,
                    ),
                }
            }
            (
                Method::Command {
                    name,
                    template,
                    format,
                },
                None,
            ) => {
                let out = out_path(work, index, name, *format);
                let (result, seconds) = run_command(template, sample, &out, size, timeout);
                outcome(result, Some(seconds))
            }
            (Method::Predictions { dir, .. }, _) => {
                outcome(read_prediction(dir, sample, size), None)
            }
            (Method::BuiltIn(m), _) => {
                let start = Instant::now();
                let result = run_built_in(*m, sample)
                    .map_err(|e| failure(FailureKind::Error, format!("{e:#}")));
                outcome(result, Some(start.elapsed().as_secs_f64()))
            }
        }
    }
}

/// A built-in method's disparity on `sample`: its two PNGs read, then the method.
fn run_built_in(method: BuiltIn, sample: &Sample) -> Result<GrayImage> {
    let left = GrayImage::load(&sample.left)
        .with_context(|| format!("reading {}", sample.left.display()))?;
    let right = GrayImage::load(&sample.right)
        .with_context(|| format!("reading {}", sample.right.display()))?;
    Ok(method.disparity(&left, &right)?)
}

/// The prediction of `sample` in the folder `dir`: `DIR/<id>.pfm` or `DIR/<id>.png`, exactly
/// one of them, of the sample's `size`.
fn read_prediction(
    dir: &Path,
    sample: &Sample,
    size: (usize, usize),
) -> std::result::Result<GrayImage, Failure> {
    let candidates: Vec<PathBuf> = MapFormat::ALL
        .iter()
        .map(|f| dir.join(format!("{}.{}", sample.id, f.extension())))
        .collect();
    let present: Vec<&PathBuf> = candidates
        .iter()
        .filter(|p| std::fs::symlink_metadata(p).is_ok())
        .collect();
    match present[..] {
        [] => Err(failure(
            FailureKind::Missing,
            format!(
                "no prediction: neither {} nor {} exists",
                candidates[0].display(),
                candidates[1].display()
            ),
        )),
        [one] => read_method_map(one, size, true).map_err(|(kind, reason)| failure(kind, reason)),
        _ => Err(failure(
            FailureKind::BadOutput,
            format!(
                "both {} and {} exist: keep the one to score",
                candidates[0].display(),
                candidates[1].display()
            ),
        )),
    }
}

/// Runs an external method's per-sample command on `sample`, writing `out`, and reads its map
/// (of the sample's `size`). A failure names why and keeps the end of the command's stderr.
fn run_command(
    template: &Template,
    sample: &Sample,
    out: &Path,
    size: (usize, usize),
    timeout: Duration,
) -> (std::result::Result<GrayImage, Failure>, f64) {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (left, right) = (abs(&sample.left), abs(&sample.right));
    if let Err(f) = remove_old(out) {
        return (Err(f), 0.0);
    }
    let paths = Paths {
        left: &left,
        right: &right,
        out,
    };
    let output = match start(&template.argv(&paths), &paths.env(), timeout) {
        Ok(o) => o,
        Err(f) => return (Err(f), 0.0),
    };
    let limit = format!("--method-timeout {} s", timeout.as_secs_f64());
    let result = match run_failure(&output, &limit) {
        Some(f) => Err(f),
        None => read_output(out, size).map_err(|mut f| {
            let (lines, chars) = FAILURE_TAIL;
            f.stderr_tail = output.stderr.text(lines, chars);
            f.stdout_tail = output.stdout.text(lines, chars);
            f
        }),
    };
    (result, output.seconds)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_specs() {
        assert!(Method::command("x=run {left} {right}").is_err());
        assert!(Method::command("sgm=run {out}").is_err());
        assert!(Method::command("no template").is_err());
        assert!(Method::command("a b=run {out}").is_err());
        assert!(Method::command("a:jpg=run {out}").is_err());
        let m = Method::command("net=python net.py {left} {right} {out}").unwrap();
        assert_eq!((m.name(), m.kind()), ("net", "command"));
        assert_eq!(
            m.description(),
            "external command: `python net.py {left} {right} {out}`"
        );
        let b = Method::command("psm:png=python run.py --list {list}").unwrap();
        assert_eq!((b.name(), b.kind()), ("psm", "batch-command"));
        assert!(matches!(
            b,
            Method::Command {
                format: MapFormat::KittiPng,
                ..
            }
        ));
        let dir = tempfile::tempdir().unwrap();
        let p = Method::predictions(&format!("mine={}", dir.path().display())).unwrap();
        assert_eq!((p.name(), p.kind()), ("mine", "predictions"));
        assert!(Method::predictions("mine=/no/such/folder").is_err());
        assert!(Method::predictions(&format!("lk={}", dir.path().display())).is_err());
    }
}
