//! The methods `streaks benchmark` runs: the built-ins ([`BuiltIn`], the analysis crate's) and
//! external commands.

use super::command::{self, Ended, Paths, Template};
use super::input::Sample;
use super::report::{Failure, FailureKind};
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::time::{Duration, Instant};
use streaks_analysis::benchmark::method::{no_value_below_zero, BuiltIn};
use streaks_image::pfm::read_pfm;
use streaks_image::GrayImage;

/// One method.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Method {
    /// A built-in method.
    BuiltIn(BuiltIn),
    /// An external command: a template with `{left}`, `{right}` and `{out}`.
    Command {
        /// The method's name.
        name: String,
        /// The template, split into words.
        template: Template,
    },
}

impl Method {
    /// The built-in method `name`.
    pub fn built_in(name: &str) -> Option<Method> {
        BuiltIn::from_name(name).map(Method::BuiltIn)
    }

    /// `--method-cmd NAME=TEMPLATE`, checked.
    pub fn command(spec: &str) -> Result<Method> {
        let Some((name, template)) = spec.split_once('=') else {
            bail!("--method-cmd {spec:?}: expected NAME=TEMPLATE");
        };
        let name = name.trim();
        let ok = |c: char| c.is_ascii_alphanumeric() || "-_.".contains(c);
        if name.is_empty() || !name.chars().all(ok) {
            bail!(
                "--method-cmd {spec:?}: the name must be letters, digits, '-', '_' or '.', \
                 got {name:?}"
            );
        }
        if Method::built_in(name).is_some() {
            bail!("--method-cmd {name}: {name} is a built-in method; choose another name");
        }
        Ok(Method::Command {
            name: name.to_string(),
            template: Template::parse(name, template)?,
        })
    }

    /// The method's name.
    pub fn name(&self) -> &str {
        match self {
            Method::BuiltIn(m) => m.name(),
            Method::Command { name, .. } => name,
        }
    }

    /// What the method is, for the report.
    pub fn description(&self) -> String {
        match self {
            Method::Command { template, .. } => {
                format!("external command: `{}`", template.text())
            }
            Method::BuiltIn(m) => m.description().to_string(),
        }
    }

    /// Runs the method on `sample` (its PNGs, the `index`-th sample), with `work` the run's
    /// private folder for a command's output and `timeout` a command's time limit. Gives the
    /// disparity of the left view (no value: `inf`; a disparity that is not finite or not
    /// positive is no value, whatever the method), or why the method failed on the sample,
    /// and the method's wall time in seconds: for a built-in, reading the two PNGs and
    /// estimating; for a command, the whole process.
    pub fn run(
        &self,
        sample: &Sample,
        index: usize,
        work: &Path,
        timeout: Duration,
    ) -> (std::result::Result<GrayImage, Failure>, f64) {
        match self {
            Method::Command { name, template } => {
                // Named by the sample's index and the checked method name: nothing of the
                // input's folder names reaches the output path.
                let out = work.join(format!("{index:06}-{name}.pfm"));
                run_command(template, sample, &out, timeout)
            }
            Method::BuiltIn(m) => {
                let start = Instant::now();
                let result = run_built_in(*m, sample).map_err(|e| Failure {
                    kind: FailureKind::Error,
                    reason: format!("{e:#}"),
                    stderr_tail: String::new(),
                    stdout_tail: String::new(),
                });
                (result, start.elapsed().as_secs_f64())
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

/// How much of a command's stderr a failure keeps: its last lines and characters.
const FAILURE_TAIL: (usize, usize) = (40, 4000);

/// Largest header a PFM of the expected size may have beside its pixels, bytes: a file
/// larger than its pixels and this is refused before it is read.
const PFM_HEADER_SLACK: u64 = 4096;

/// Runs an external method's command on `sample`, writing `out`, and reads its PFM. A failure
/// names why and keeps the end of the command's stderr.
fn run_command(
    template: &Template,
    sample: &Sample,
    out: &Path,
    timeout: Duration,
) -> (std::result::Result<GrayImage, Failure>, f64) {
    let fail = |kind, reason: String| Failure {
        kind,
        reason,
        stderr_tail: String::new(),
        stdout_tail: String::new(),
    };
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (left, right, out) = (abs(&sample.left), abs(&sample.right), abs(out));
    // A leftover of any earlier run is never taken for this run's output.
    match std::fs::remove_file(&out) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return (
                Err(fail(
                    FailureKind::Error,
                    format!("cannot remove the old output {}: {e}", out.display()),
                )),
                0.0,
            )
        }
        _ => {}
    }
    let paths = Paths {
        left: &left,
        right: &right,
        out: &out,
    };
    let argv = template.argv(&paths);
    let output = match command::run(&argv, &paths.env(), timeout) {
        Ok(o) => o,
        Err(e) => {
            let program = argv
                .first()
                .map(|p| p.to_string_lossy())
                .unwrap_or_default();
            return (
                Err(fail(
                    FailureKind::Spawn,
                    format!("cannot run {program:?}: {e}"),
                )),
                0.0,
            );
        }
    };
    let seconds = output.seconds;
    let (lines, chars) = FAILURE_TAIL;
    let failed = |kind, mut reason: String| {
        if output.output_left_open {
            reason
                .push_str("; a process it started left its process group and held its output open");
        }
        (
            Err(Failure {
                kind,
                reason,
                stderr_tail: output.stderr.text(lines, chars),
                stdout_tail: output.stdout.text(lines, chars),
            }),
            seconds,
        )
    };
    let status = match output.ended {
        Ended::TimedOut => {
            return failed(
                FailureKind::Timeout,
                format!(
                    "ran longer than --method-timeout {} s: its process group was killed",
                    timeout.as_secs_f64()
                ),
            )
        }
        Ended::Status(s) => s,
    };
    if !status.success() {
        use std::os::unix::process::ExitStatusExt;
        return match status.signal() {
            Some(sig) => failed(FailureKind::Signal, format!("killed by signal {sig}")),
            None => failed(
                FailureKind::Exit,
                format!("exited with status {}", status.code().unwrap_or(-1)),
            ),
        };
    }
    let meta = match std::fs::symlink_metadata(&out) {
        Ok(m) => m,
        Err(_) => {
            return failed(
                FailureKind::NoOutput,
                format!("exited with status 0 but wrote no {}", out.display()),
            )
        }
    };
    let Ok((w, h)) = image::image_dimensions(&sample.left) else {
        return failed(
            FailureKind::Error,
            format!("cannot read the size of {}", sample.left.display()),
        );
    };
    let most = u64::from(w) * u64::from(h) * 4 + PFM_HEADER_SLACK;
    if !meta.file_type().is_file() {
        return failed(
            FailureKind::BadOutput,
            format!(
                "its output {} is not a regular file (a link, folder or device)",
                out.display()
            ),
        );
    }
    if meta.len() > most {
        return failed(
            FailureKind::BadOutput,
            format!(
                "its output is {} bytes, more than a {w}x{h} PFM's {most}",
                meta.len()
            ),
        );
    }
    let mut disp = match read_pfm(&out) {
        Ok(d) => d,
        Err(e) => {
            return failed(
                FailureKind::BadOutput,
                format!("its output is not a readable PFM: {e}"),
            )
        }
    };
    if (disp.width as u64, disp.height as u64) != (u64::from(w), u64::from(h)) {
        return failed(
            FailureKind::BadOutput,
            format!(
                "it wrote a {}x{} disparity map, the sample is {w}x{h}",
                disp.width, disp.height
            ),
        );
    }
    no_value_below_zero(&mut disp);
    (Ok(disp), seconds)
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
        let m = Method::command("net=python net.py {left} {right} {out}").unwrap();
        assert_eq!(m.name(), "net");
        assert_eq!(
            m.description(),
            "external command: `python net.py {left} {right} {out}`"
        );
    }
}
