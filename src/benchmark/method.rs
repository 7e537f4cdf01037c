//! The methods `streaks benchmark` runs: the built-ins and external commands.

use super::input::Sample;
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::process::Command;
use std::time::Instant;
use streaks_analysis::benchmark::{lk_streak_disparity, streak_lk_params};
use streaks_analysis::detect::DetectParams;
use streaks_analysis::repair::StreakHandling;
use streaks_analysis::sgm::SgmParams;
use streaks_image::pfm::read_pfm;
use streaks_image::GrayImage;

/// The built-in methods, by name.
pub const BUILT_INS: [(&str, &str); 3] = [
    (
        "sgm",
        "semi-global matching as `streaks disparity` computes it (census 7x7, 8 paths, \
         disparities 0-63, left-right check, median)",
    ),
    (
        "sgm-streaks",
        "sgm, then the streak repair: `streaks disparity --streaks repair` (road plane from \
         the pair's v-disparity; detected streaks and below-the-road pixels given the plane's \
         disparity)",
    ),
    (
        "lk",
        "the paper's per-row Lucas-Kanade along each detected streak's centre, as `streaks \
         analyze` measures it: values only on detected streak rows (a small valid share)",
    ),
];

/// One method.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Method {
    /// `sgm`.
    Sgm,
    /// `sgm-streaks`.
    SgmStreaks,
    /// `lk`.
    Lk,
    /// An external command: a template with `{left}`, `{right}` and `{out}`.
    Command {
        /// The method's name.
        name: String,
        /// The template.
        template: String,
    },
}

impl Method {
    /// The built-in method `name`.
    pub fn built_in(name: &str) -> Option<Method> {
        match name {
            "sgm" => Some(Method::Sgm),
            "sgm-streaks" => Some(Method::SgmStreaks),
            "lk" => Some(Method::Lk),
            _ => None,
        }
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
        if !template.contains("{out}") {
            bail!(
                "--method-cmd {name}: the template {template:?} has no {{out}}, the PFM the \
                 command must write (use {{left}}, {{right}} and {{out}})"
            );
        }
        Ok(Method::Command {
            name: name.to_string(),
            template: template.to_string(),
        })
    }

    /// The method's name.
    pub fn name(&self) -> &str {
        match self {
            Method::Sgm => "sgm",
            Method::SgmStreaks => "sgm-streaks",
            Method::Lk => "lk",
            Method::Command { name, .. } => name,
        }
    }

    /// What the method is, for the report.
    pub fn description(&self) -> String {
        match self {
            Method::Command { template, .. } => format!("external command: {template}"),
            m => BUILT_INS
                .iter()
                .find(|(n, _)| *n == m.name())
                .map(|(_, d)| d.to_string())
                .unwrap_or_default(),
        }
    }

    /// Runs the method on `sample` (its PNGs), with `work` a folder for the command's output.
    /// Returns the disparity of the left view (no value: `inf`; a disparity that is not
    /// finite or not positive is no value, whatever the method) and the method's wall time in
    /// seconds: for a built-in, reading the two PNGs and estimating; for a command, the whole
    /// process.
    pub fn run(&self, sample: &Sample, work: &Path) -> Result<(GrayImage, f64)> {
        let start = Instant::now();
        let mut disp = match self {
            Method::Sgm | Method::SgmStreaks | Method::Lk => {
                let left = GrayImage::load(&sample.left)
                    .with_context(|| format!("reading {}", sample.left.display()))?;
                let right = GrayImage::load(&sample.right)
                    .with_context(|| format!("reading {}", sample.right.display()))?;
                match self {
                    Method::Sgm => {
                        crate::disparity::estimate(&left, &right, &SgmParams::default(), None)?
                            .disparity
                    }
                    Method::SgmStreaks => {
                        crate::disparity::estimate(
                            &left,
                            &right,
                            &SgmParams::default(),
                            Some(StreakHandling::Repair),
                        )?
                        .disparity
                    }
                    _ => lk_streak_disparity(
                        &left,
                        &right,
                        &streak_lk_params(),
                        &DetectParams::default(),
                    )?,
                }
            }
            Method::Command { name, template } => {
                let out = work.join(format!("{}-{name}.pfm", sample.id));
                return run_command(name, template, sample, &out);
            }
        };
        let seconds = start.elapsed().as_secs_f64();
        no_value_below_zero(&mut disp);
        Ok((disp, seconds))
    }
}

/// Makes every disparity that is not finite or not positive `inf` (no value).
fn no_value_below_zero(disp: &mut GrayImage) {
    for v in &mut disp.data {
        if !(v.is_finite() && *v > 0.0) {
            *v = f32::INFINITY;
        }
    }
}

/// `s` quoted for `sh`: in single quotes, each `'` written `'\''`.
pub fn shell_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The last `lines` lines of `text` (at most 2000 characters).
fn tail(text: &str, lines: usize) -> String {
    let all: Vec<&str> = text.trim_end().lines().collect();
    let t = all[all.len().saturating_sub(lines)..].join("\n");
    match t.char_indices().rev().nth(1999) {
        Some((i, _)) => format!("...{}", &t[i..]),
        None => t,
    }
}

/// Runs an external method's command on `sample`, writing `out`, and reads its PFM.
fn run_command(
    name: &str,
    template: &str,
    sample: &Sample,
    out: &Path,
) -> Result<(GrayImage, f64)> {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let line = template
        .replace("{left}", &shell_quote(&abs(&sample.left).to_string_lossy()))
        .replace(
            "{right}",
            &shell_quote(&abs(&sample.right).to_string_lossy()),
        )
        .replace("{out}", &shell_quote(&abs(out).to_string_lossy()));
    let what = || format!("method {name} on sample {}", sample.id);
    let start = Instant::now();
    let output = Command::new("sh")
        .arg("-c")
        .arg(&line)
        .stdin(std::process::Stdio::null())
        .output()
        .with_context(|| format!("{}: cannot run sh -c {line:?}", what()))?;
    let seconds = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        bail!(
            "{}: the command failed ({}): {line}\nits stderr ended:\n{}",
            what(),
            output.status,
            tail(&stderr, 12)
        );
    }
    if !out.is_file() {
        bail!(
            "{}: the command succeeded but wrote no {}: {line}\nits stderr ended:\n{}",
            what(),
            out.display(),
            tail(&stderr, 12)
        );
    }
    let mut disp = read_pfm(out).with_context(|| format!("{}: reading its output", what()))?;
    let truth_size = image::image_dimensions(&sample.left)
        .with_context(|| format!("reading the size of {}", sample.left.display()))?;
    if (disp.width as u32, disp.height as u32) != truth_size {
        bail!(
            "{}: the command wrote a {}x{} disparity map, the sample is {}x{}: {line}",
            what(),
            disp.width,
            disp.height,
            truth_size.0,
            truth_size.1
        );
    }
    no_value_below_zero(&mut disp);
    Ok((disp, seconds))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_and_templates() {
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
        assert!(Method::command("x=run {left} {right}").is_err());
        assert!(Method::command("sgm=run {out}").is_err());
        assert!(Method::command("no template").is_err());
        assert!(Method::command("a b=run {out}").is_err());
        let m = Method::command("net=python net.py {left} {right} {out}").unwrap();
        assert_eq!(m.name(), "net");
        assert_eq!(tail("a\nb\nc\n", 2), "b\nc");
    }
}
