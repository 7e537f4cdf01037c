//! External methods' commands, run without a shell: a template split into words once, its
//! placeholders replaced in one pass, and a process run in its own process group with a time
//! limit and bounded output.
//!
//! - [`Template`]: `--method-cmd NAME=TEMPLATE`'s TEMPLATE, split into argv words by shell word
//!   rules (`shlex`, quotes and backslashes; no expansion, no operators) before any path is
//!   known; [`Template::argv`] then replaces `{left}`, `{right}` and `{out}` inside each word in
//!   a single left-to-right pass, so a path that itself reads `{out}` stays literal. A *batch*
//!   template names `{list}` instead ([`Template::is_batch`]): one run for all samples, given
//!   a list file ([`write_list`]) by [`Template::batch_argv`].
//! - [`run`]: runs the words as a program (stdin from `/dev/null`, the paths also in the
//!   environment as [`ENV_LEFT`], [`ENV_RIGHT`], [`ENV_OUT`]) in a fresh process group; on the
//!   time limit the whole group is killed, and once the program ends its group is killed too,
//!   so a child left behind cannot hold the output pipes open. Being in its own group, the
//!   command does not get the terminal's Ctrl-C: SIGINT, SIGTERM and SIGHUP to `streaks` kill
//!   the running command's group before `streaks` dies of them. Stdout and stderr are read by
//!   two threads that keep only their last [`TAIL_BYTES`].

use anyhow::{bail, Result};
use std::ffi::{OsStr, OsString};
use std::io::Read;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicI32, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// The environment variable holding the left PNG's absolute path.
pub const ENV_LEFT: &str = "STREAKS_LEFT";
/// The environment variable holding the right PNG's absolute path.
pub const ENV_RIGHT: &str = "STREAKS_RIGHT";
/// The environment variable holding the absolute path of the PFM the command must write.
pub const ENV_OUT: &str = "STREAKS_OUT";
/// The environment variable holding a batch command's list file ([`write_list`]).
pub const ENV_LIST: &str = "STREAKS_LIST";

/// A batch command's list placeholder.
const LIST: &str = "{list}";

/// How much of each of a command's output streams is kept: its last 64 KiB.
pub const TAIL_BYTES: usize = 64 * 1024;

/// How long the output readers get to finish once the command's process group is gone; only a
/// process that left the group (its own session) can keep a pipe open longer.
const DRAIN_GRACE: Duration = Duration::from_secs(2);

/// The per-sample placeholders, in the order of [`Paths`]' fields.
const PLACEHOLDERS: [&str; 3] = ["{left}", "{right}", "{out}"];

/// Programs whose `-c` or `-e` option takes code: a placeholder inside that code would put a
/// path into program text, the very thing the template's word rules exist to avoid.
const INTERPRETERS: [&str; 14] = [
    "sh", "bash", "dash", "zsh", "ksh", "mksh", "ash", "fish", "python", "python3", "perl", "ruby",
    "node", "pwsh",
];

/// The three paths a command receives.
#[derive(Clone, Copy, Debug)]
pub struct Paths<'a> {
    /// The left PNG.
    pub left: &'a Path,
    /// The right PNG.
    pub right: &'a Path,
    /// The PFM to write.
    pub out: &'a Path,
}

impl Paths<'_> {
    /// Each placeholder of [`PLACEHOLDERS`] with its value.
    fn values(&self) -> [(&'static str, &OsStr); 3] {
        [
            (PLACEHOLDERS[0], self.left.as_os_str()),
            (PLACEHOLDERS[1], self.right.as_os_str()),
            (PLACEHOLDERS[2], self.out.as_os_str()),
        ]
    }

    /// The environment the command gets: [`ENV_LEFT`], [`ENV_RIGHT`], [`ENV_OUT`].
    pub fn env(&self) -> [(&'static str, &OsStr); 3] {
        [
            (ENV_LEFT, self.left.as_os_str()),
            (ENV_RIGHT, self.right.as_os_str()),
            (ENV_OUT, self.out.as_os_str()),
        ]
    }
}

/// A command template, split into words.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Template {
    /// The template as given.
    text: String,
    /// Its words, placeholders still in them.
    words: Vec<String>,
    /// Whether it names `{list}` (or [`ENV_LIST`]): one run for all samples.
    batch: bool,
}

/// Whether `word` holds a placeholder, `{list}` included.
fn has_placeholder(word: &str) -> bool {
    PLACEHOLDERS.iter().chain([&LIST]).any(|p| word.contains(p))
}

/// The program name of `word` without its folder and a version suffix (`python3.12` ->
/// `python3`, `/usr/bin/bash` -> `bash`).
fn program_name(word: &str) -> &str {
    let base = word.rsplit('/').next().unwrap_or(word);
    match base.find(['.', '-']) {
        Some(i)
            if base[i + 1..]
                .chars()
                .all(|c| c.is_ascii_digit() || c == '.') =>
        {
            &base[..i]
        }
        _ => base,
    }
}

/// Whether `flag` is an option after which an interpreter reads code: `-c` (or a cluster ending
/// in it, `-ec`), `-e`, `-E`, `--eval`, `--command`.
fn is_code_flag(flag: &str) -> bool {
    if matches!(flag, "-e" | "-E" | "--eval" | "--command" | "-Command") {
        return true;
    }
    flag.len() >= 2
        && flag.starts_with('-')
        && !flag.starts_with("--")
        && flag.ends_with('c')
        && flag[1..].chars().all(|c| c.is_ascii_alphabetic())
}

impl Template {
    /// Splits `text` into words (shell word rules: blanks separate words; single quotes, double
    /// quotes and backslashes keep blanks in a word; `#` at a word's start begins a comment; no
    /// variable, command or glob expansion, no `;`, `|`, `>` operators: those are plain
    /// characters of a word). `name` is the method's, for errors.
    ///
    /// A template that names `{list}` or [`ENV_LIST`] is a batch template, run once for all
    /// samples; it cannot also name `{left}`, `{right}` or `{out}`.
    ///
    /// Refused: unbalanced quotes, no words, a placeholder in the program word, a template
    /// naming neither `{out}` nor [`ENV_OUT`] (nor, for a batch, `{list}` or [`ENV_LIST`]), a
    /// batch template with a per-sample placeholder, and a placeholder inside the code an
    /// interpreter runs (`sh -c '... {left} ...'`), which would put a path into program
    /// text.
    pub fn parse(name: &str, text: &str) -> Result<Template> {
        let Some(words) = shlex::split(text) else {
            bail!(
                "--method-cmd {name}: the template {text:?} has an unclosed quote or a trailing \
                 backslash"
            );
        };
        let Some(program) = words.first() else {
            bail!("--method-cmd {name}: the template is empty");
        };
        if has_placeholder(program) {
            bail!(
                "--method-cmd {name}: the program {program:?} cannot be a placeholder; the first \
                 word is the program to run"
            );
        }
        let batch = words.iter().any(|w| w.contains(LIST)) || text.contains(ENV_LIST);
        if batch {
            if let Some(w) = words
                .iter()
                .find(|w| PLACEHOLDERS.iter().any(|p| w.contains(p)))
            {
                bail!(
                    "--method-cmd {name}: the template names {{list}} (one run for all samples) \
                     and also {w:?}: a batch command reads each sample's paths from the list \
                     file, a per-sample command gets {{left}}, {{right}} and {{out}}; not both"
                );
            }
        } else if !words.iter().any(|w| w.contains("{out}")) && !text.contains(ENV_OUT) {
            bail!(
                "--method-cmd {name}: the template {text:?} has no {{out}} (nor ${ENV_OUT}), the \
                 PFM the command must write (use {{left}}, {{right}} and {{out}}, or {{list}} \
                 for one run over all samples)"
            );
        }
        for (i, w) in words.iter().enumerate() {
            if !INTERPRETERS.contains(&program_name(w)) {
                continue;
            }
            let mut rest = words[i + 1..].iter();
            while let Some(flag) = rest.next() {
                if !flag.starts_with('-') {
                    break;
                }
                if is_code_flag(flag) {
                    if let Some(code) = rest.next().filter(|c| has_placeholder(c)) {
                        bail!(
                            "--method-cmd {name}: a placeholder inside the code {w} {flag} runs \
                             ({code:?}) would make a path part of program text; read the paths \
                             from the environment instead (\"${ENV_LEFT}\", \"${ENV_RIGHT}\", \
                             \"${ENV_OUT}\", \"${ENV_LIST}\"), or pass them as arguments \
                             after the code \
                             (sh -c '... \"$1\" \"$2\" \"$3\"' sh {{left}} {{right}} {{out}})"
                        );
                    }
                    break;
                }
            }
        }
        Ok(Template {
            text: text.to_string(),
            words,
            batch,
        })
    }

    /// Whether it is a batch template (`{list}`): one run for all samples.
    pub fn is_batch(&self) -> bool {
        self.batch
    }

    /// The template as given.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The argv of a run: each word with `{left}`, `{right}` and `{out}` replaced by `paths`
    /// in one left-to-right pass. A replacement is never scanned again, so a path holding
    /// `{out}` or quotes stays exactly itself; any other brace is left as it is.
    pub fn argv(&self, paths: &Paths) -> Vec<OsString> {
        let values = paths.values();
        self.words.iter().map(|w| substitute(w, &values)).collect()
    }

    /// The argv of a batch run: each word with `{list}` replaced by `list`, as
    /// [`Template::argv`] replaces the per-sample placeholders.
    pub fn batch_argv(&self, list: &Path) -> Vec<OsString> {
        let values = [(LIST, list.as_os_str())];
        self.words.iter().map(|w| substitute(w, &values)).collect()
    }
}

/// One line of a batch command's list file: the three absolute paths, tab-separated, or why a
/// path cannot be written in it (not UTF-8, or holding a tab, newline or carriage return).
fn list_line(paths: &Paths) -> std::result::Result<String, String> {
    let mut fields = Vec::with_capacity(3);
    for p in [paths.left, paths.right, paths.out] {
        let Some(text) = p.to_str() else {
            return Err(format!("{} is not UTF-8 text", p.display()));
        };
        if text.contains(['\t', '\n', '\r']) {
            return Err(format!(
                "{text:?} holds a tab, newline or carriage return, which separate the list's \
                 fields and lines"
            ));
        }
        fields.push(text);
    }
    Ok(format!("{}\n", fields.join("\t")))
}

/// Writes a batch command's list file `list`: one line per sample, `left<TAB>right<TAB>out`,
/// absolute paths in UTF-8, each line ended by a newline. A path that cannot be written so
/// ([`list_line`]) is refused with the path and the reason, before the file is written.
pub fn write_list(list: &Path, samples: &[Paths]) -> Result<()> {
    let mut text = String::new();
    for p in samples {
        match list_line(p) {
            Ok(line) => text.push_str(&line),
            Err(reason) => bail!(
                "a batch command's list file cannot hold this sample's paths: {reason}; rename \
                 the folder or use a per-sample template ({{left}} {{right}} {{out}})"
            ),
        }
    }
    streaks_image::write_bytes_atomically(list, text.as_bytes())?;
    Ok(())
}

/// `word` with the placeholders of `values` replaced in one pass.
fn substitute(word: &str, values: &[(&str, &OsStr)]) -> OsString {
    let mut out = OsString::with_capacity(word.len());
    let mut rest = word;
    while let Some(i) = rest.find('{') {
        out.push(&rest[..i]);
        let from = &rest[i..];
        match values.iter().find(|(p, _)| from.starts_with(p)) {
            Some((p, value)) => {
                out.push(value);
                rest = &from[p.len()..];
            }
            None => {
                out.push("{");
                rest = &from[1..];
            }
        }
    }
    out.push(rest);
    out
}

/// The last bytes of an output stream, and how many it had in all.
#[derive(Clone, Debug, Default)]
pub struct Tail {
    /// At most [`TAIL_BYTES`]: the stream's end.
    pub bytes: Vec<u8>,
    /// The stream's whole length.
    pub total: u64,
}

impl Tail {
    /// Appends `chunk`, keeping at most `2 * TAIL_BYTES` (trimmed to [`TAIL_BYTES`] when full,
    /// so the work per byte stays constant).
    fn push(&mut self, chunk: &[u8]) {
        self.total += chunk.len() as u64;
        self.bytes.extend_from_slice(chunk);
        if self.bytes.len() > 2 * TAIL_BYTES {
            self.bytes.drain(..self.bytes.len() - TAIL_BYTES);
        }
    }

    /// Its end as text: the last `max_lines` lines and at most `max_chars` characters (lossy
    /// UTF-8, carriage returns dropped, other control characters but newlines and tabs
    /// replaced), with `...` when cut.
    pub fn text(&self, max_lines: usize, max_chars: usize) -> String {
        let start = self.bytes.len().saturating_sub(TAIL_BYTES);
        // Control characters (terminal escapes, NULs) become U+FFFD: the text is printed to a
        // terminal and put on a page.
        let text: String = String::from_utf8_lossy(&self.bytes[start..])
            .chars()
            .filter(|&c| c != '\r')
            .map(|c| match c {
                '\n' | '\t' => c,
                c if c.is_control() => char::REPLACEMENT_CHARACTER,
                c => c,
            })
            .collect();
        let text = text.trim_end();
        let lines: Vec<&str> = text.lines().collect();
        let kept = lines[lines.len().saturating_sub(max_lines)..].join("\n");
        let cut = kept.len() < text.len() || (self.total as usize) > self.bytes.len();
        let kept = match kept.char_indices().rev().nth(max_chars.saturating_sub(1)) {
            Some((i, _)) => kept[i..].to_string(),
            None => kept,
        };
        if cut && !kept.is_empty() {
            format!("...{kept}")
        } else {
            kept
        }
    }
}

/// A thread reading one stream into a [`Tail`].
struct TailReader {
    tail: Arc<Mutex<Tail>>,
    done: mpsc::Receiver<()>,
}

impl TailReader {
    /// Starts reading `stream`.
    fn start(mut stream: impl Read + Send + 'static) -> Self {
        let tail = Arc::new(Mutex::new(Tail::default()));
        let (tx, done) = mpsc::channel();
        let shared = Arc::clone(&tail);
        std::thread::spawn(move || {
            let mut buf = vec![0u8; TAIL_BYTES];
            loop {
                match stream.read(&mut buf) {
                    Ok(0) => break,
                    Ok(n) => match shared.lock() {
                        Ok(mut t) => t.push(&buf[..n]),
                        Err(_) => break,
                    },
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(_) => break,
                }
            }
            let _ = tx.send(());
        });
        Self { tail, done }
    }

    /// The tail once the stream ends, waiting at most `grace`; `false` beside it when the
    /// stream was still open (the thread is left to finish on its own).
    fn finish(self, grace: Duration) -> (Tail, bool) {
        let ended = !matches!(
            self.done.recv_timeout(grace),
            Err(mpsc::RecvTimeoutError::Timeout)
        );
        let tail = match self.tail.lock() {
            Ok(t) => t.clone(),
            Err(p) => p.into_inner().clone(),
        };
        (tail, ended)
    }
}

/// How a command ended.
#[derive(Clone, Copy, Debug)]
pub enum Ended {
    /// It ended on its own, with this status (an exit code or a signal).
    Status(ExitStatus),
    /// It ran past the time limit and its process group was killed.
    TimedOut,
}

/// What a run of a command gave.
#[derive(Debug)]
pub struct Output {
    /// How it ended.
    pub ended: Ended,
    /// Its wall time, seconds (up to the end of the program, not of the output readers).
    pub seconds: f64,
    /// The end of its stdout.
    pub stdout: Tail,
    /// The end of its stderr.
    pub stderr: Tail,
    /// Whether a process that left the command's group still held an output stream open when
    /// the run gave up waiting for it.
    pub output_left_open: bool,
}

/// The process group of the command running now (0: none), for the signal handler.
static RUNNING_GROUP: AtomicI32 = AtomicI32::new(0);

/// On SIGINT, SIGTERM or SIGHUP: kills the running command's group (it is not in the
/// terminal's foreground group, so Ctrl-C does not reach it), then dies of the signal as it
/// would have without the handler.
extern "C" fn on_terminating_signal(sig: libc::c_int) {
    let pgid = RUNNING_GROUP.load(Ordering::SeqCst);
    // SAFETY: killpg, signal and raise are async-signal-safe.
    unsafe {
        if pgid > 0 {
            libc::killpg(pgid, libc::SIGKILL);
        }
        libc::signal(sig, libc::SIG_DFL);
        libc::raise(sig);
    }
}

/// Installs [`on_terminating_signal`] once, for the signals that end the process by default
/// (a signal the process ignores stays ignored).
fn install_signal_handler() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            // SAFETY: the handler only touches an atomic and calls async-signal-safe functions.
            unsafe {
                let handler = on_terminating_signal as extern "C" fn(libc::c_int);
                let old = libc::signal(sig, handler as libc::sighandler_t);
                if old == libc::SIG_IGN {
                    libc::signal(sig, libc::SIG_IGN);
                }
            }
        }
    });
}

/// Sends SIGKILL to the process group `pgid` (nothing when it is already empty).
fn kill_group(pgid: libc::pid_t) {
    // SAFETY: killpg only sends a signal; `pgid` is the group this run created for its child,
    // whose leader is not yet reaped, so the id cannot have been reused.
    unsafe {
        libc::killpg(pgid, libc::SIGKILL);
    }
}

/// A running command's process group: registered for the signal handler while it lives, and
/// killed when dropped (on every way out of [`run`]).
struct Group(libc::pid_t);

impl Group {
    /// Registers the group `pgid`.
    fn new(pgid: libc::pid_t) -> Self {
        RUNNING_GROUP.store(pgid, Ordering::SeqCst);
        Self(pgid)
    }
}

impl Drop for Group {
    fn drop(&mut self) {
        kill_group(self.0);
        RUNNING_GROUP.store(0, Ordering::SeqCst);
    }
}

/// Whether the child `pid` has ended, without reaping it (so its pid, the process group's id,
/// stays reserved until [`std::process::Child::wait`]). `block`: wait until it has.
fn has_ended(pid: libc::pid_t, block: bool) -> std::io::Result<bool> {
    let mut flags = libc::WEXITED | libc::WNOWAIT;
    if !block {
        flags |= libc::WNOHANG;
    }
    loop {
        // SAFETY: a zeroed siginfo_t is a valid value; waitid writes into it and reads nothing
        // else; `pid` is our own unreaped child.
        let mut info: libc::siginfo_t = unsafe { std::mem::zeroed() };
        let r = unsafe { libc::waitid(libc::P_PID, pid as libc::id_t, &mut info, flags) };
        if r == 0 {
            // With WNOHANG and nothing to report, waitid leaves the zeroed info as it is; a
            // report is a SIGCHLD.
            return Ok(info.si_signo == libc::SIGCHLD);
        }
        let err = std::io::Error::last_os_error();
        if err.kind() != std::io::ErrorKind::Interrupted {
            return Err(err);
        }
    }
}

/// Runs `argv` (program, then arguments) with `env` added to the environment, stdin from
/// `/dev/null`, in a process group of its own, for at most `timeout` (see the module
/// documentation). An error only when the program cannot be started or waited for.
pub fn run(
    argv: &[OsString],
    env: &[(&str, &OsStr)],
    timeout: Duration,
) -> std::io::Result<Output> {
    let Some((program, args)) = argv.split_first() else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "no program to run",
        ));
    };
    let mut cmd = Command::new(program);
    cmd.args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0);
    install_signal_handler();
    let start = Instant::now();
    let mut child = cmd.spawn()?;
    let pid = child.id() as libc::pid_t;
    let group = Group::new(pid);
    let stdout = child.stdout.take().map(TailReader::start);
    let stderr = child.stderr.take().map(TailReader::start);
    let mut poll = Duration::from_millis(2);
    let timed_out = loop {
        if has_ended(pid, false)? {
            break false;
        }
        let elapsed = start.elapsed();
        if elapsed >= timeout {
            kill_group(pid);
            has_ended(pid, true)?;
            break true;
        }
        std::thread::sleep(poll.min(timeout - elapsed));
        poll = (poll * 2).min(Duration::from_millis(50));
    };
    let seconds = start.elapsed().as_secs_f64();
    // Whatever the program left behind in its group goes with it (before the leader is
    // reaped, while the group's id is still reserved).
    drop(group);
    let status = child.wait()?;
    let drained_by = Instant::now() + DRAIN_GRACE;
    let finish = |r: Option<TailReader>| match r {
        Some(r) => r.finish(drained_by.saturating_duration_since(Instant::now())),
        None => (Tail::default(), true),
    };
    let ((stdout, out_ended), (stderr, err_ended)) = (finish(stdout), finish(stderr));
    Ok(Output {
        ended: if timed_out {
            Ended::TimedOut
        } else {
            Ended::Status(status)
        },
        seconds,
        stdout,
        stderr,
        output_left_open: !(out_ended && err_ended),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn argv(template: &str, left: &str, right: &str, out: &str) -> Vec<OsString> {
        let (l, r, o) = (
            PathBuf::from(left),
            PathBuf::from(right),
            PathBuf::from(out),
        );
        Template::parse("m", template).unwrap().argv(&Paths {
            left: &l,
            right: &r,
            out: &o,
        })
    }

    fn strings(v: &[&str]) -> Vec<OsString> {
        v.iter().map(OsString::from).collect()
    }

    #[test]
    fn words_then_one_pass_substitution() {
        assert_eq!(
            argv(
                "net.py {left} {right} {out}",
                "/a/l.png",
                "/a/r.png",
                "/w/o.pfm"
            ),
            strings(&["net.py", "/a/l.png", "/a/r.png", "/w/o.pfm"])
        );
        // Inside words, and quoted blanks in the template.
        assert_eq!(
            argv(
                "run --left={left} 'two words' \"--out {out}\" x{right}y",
                "/l",
                "/r",
                "/o"
            ),
            strings(&["run", "--left=/l", "two words", "--out /o", "x/ry"])
        );
        // A path holding a placeholder, quotes, `$(...)`, blanks, a newline: literal.
        let nasty = "/d/{out} it's \"$(touch PWNED)\" `id`;\nrm -rf ~ {left}";
        let got = argv("m {left} {right} {out}", nasty, "/r", "/o");
        assert_eq!(
            got,
            [OsString::from("m"), nasty.into(), "/r".into(), "/o".into()]
        );
        // One pass: a value ending in `{` and a template word going on with `out}` do not
        // make a new placeholder, nor do unknown braces change.
        assert_eq!(
            argv("p {left}out} {x} {} {{out}}", "/a{", "/r", "/o"),
            strings(&["p", "/a{out}", "{x}", "{}", "{/o}"])
        );
        // Shell syntax is plain text: no operators, no expansion.
        assert_eq!(
            argv("p {out} ; rm -rf $HOME | x > y", "/l", "/r", "/o"),
            strings(&["p", "/o", ";", "rm", "-rf", "$HOME", "|", "x", ">", "y"])
        );
    }

    #[test]
    fn bad_templates_are_refused() {
        let err = |t: &str| format!("{:#}", Template::parse("m", t).unwrap_err());
        assert!(err("run {left} {right}").contains("has no {out}"));
        assert!(err("run 'unclosed {out}").contains("unclosed quote"));
        assert!(err("   ").contains("empty"));
        assert!(err("{left} {out}").contains("cannot be a placeholder"));
        for t in [
            "sh -c 'prog {left} > {out}'",
            "/bin/bash -ec 'prog {out}'",
            "env python3.12 -c 'open(\"{out}\")'",
            "perl -e 'print \"{out}\"'",
        ] {
            assert!(err(t).contains("program text"), "{t}");
        }
        // Arguments after the code, and the environment, are fine.
        for t in [
            "sh -c 'prog \"$1\" > \"$2\"' sh {left} {out}",
            "sh -c 'prog \"$STREAKS_LEFT\" > \"$STREAKS_OUT\"'",
            "python3 net.py -c cfg.toml {left} {right} {out}",
            "tool -c {left} {out}",
        ] {
            assert!(Template::parse("m", t).is_ok(), "{t}");
        }
    }

    #[test]
    fn batch_templates_and_their_list_file() {
        let t = Template::parse("b", "net --list={list} -v").unwrap();
        assert!(t.is_batch());
        assert_eq!(
            t.batch_argv(Path::new("/w/{out} list.tsv")),
            strings(&["net", "--list=/w/{out} list.tsv", "-v"])
        );
        assert!(Template::parse("b", "sh -c 'net \"$STREAKS_LIST\"'")
            .unwrap()
            .is_batch());
        assert!(!Template::parse("b", "net {left} {right} {out}")
            .unwrap()
            .is_batch());
        let err = |t: &str| format!("{:#}", Template::parse("b", t).unwrap_err());
        assert!(err("net {list} {out}").contains("not both"));
        assert!(err("sh -c 'net {list}'").contains("program text"));
        assert!(err("{list}").contains("cannot be a placeholder"));
        // The list: tab-separated absolute paths, one sample a line; blanks and quotes kept.
        let dir = tempfile::tempdir().unwrap();
        let list = dir.path().join("list.tsv");
        let (l, r, o) = (
            PathBuf::from("/d/it's a {left}/im0.png"),
            PathBuf::from("/d/im1.png"),
            PathBuf::from("/w/000000-net.pfm"),
        );
        let p = Paths {
            left: &l,
            right: &r,
            out: &o,
        };
        write_list(&list, &[p, p]).unwrap();
        let line = "/d/it's a {left}/im0.png\t/d/im1.png\t/w/000000-net.pfm\n";
        assert_eq!(
            std::fs::read_to_string(&list).unwrap(),
            format!("{line}{line}")
        );
        // A tab or a newline in a path cannot be written: refused, nothing written.
        for bad in ["/d/a\tb/im0.png", "/d/a\nb/im0.png"] {
            let l = PathBuf::from(bad);
            let other = dir.path().join("other.tsv");
            let e = write_list(&other, &[Paths { left: &l, ..p }]).unwrap_err();
            assert!(format!("{e:#}").contains("tab, newline"), "{e:#}");
            assert!(!other.exists());
        }
    }

    #[test]
    fn tails_keep_the_end() {
        let mut t = Tail::default();
        for _ in 0..100 {
            t.push(&[b'a'; 10_000]);
        }
        t.push(b"\nlast line\n");
        assert!(t.bytes.len() <= 2 * TAIL_BYTES);
        assert_eq!(t.total, 1_000_011);
        assert_eq!(t.text(1, 100), "...last line");
        assert_eq!(t.text(5, 4), "...line");
        let mut short = Tail::default();
        short.push(b"a\nb\n");
        assert_eq!(short.text(5, 100), "a\nb");
        let mut esc = Tail::default();
        esc.push(b"\x1b[2Jred\0\tx\r\n");
        assert_eq!(esc.text(5, 100), "\u{FFFD}[2Jred\u{FFFD}\tx");
    }

    #[test]
    fn a_run_times_out_and_kills_its_group() {
        let sh = |script: &str| strings(&["sh", "-c", script]);
        let start = Instant::now();
        let out = run(
            &sh("sleep 30 & echo started; sleep 30"),
            &[],
            Duration::from_millis(300),
        )
        .unwrap();
        assert!(matches!(out.ended, Ended::TimedOut));
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "{:?}",
            start.elapsed()
        );
        assert_eq!(out.stdout.text(5, 100), "started");
        // A child left behind by a program that ends does not keep the run waiting.
        let start = Instant::now();
        let out = run(&sh("sleep 30 & exit 0"), &[], Duration::from_secs(20)).unwrap();
        assert!(matches!(out.ended, Ended::Status(s) if s.success()));
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "{:?}",
            start.elapsed()
        );
        assert!(!out.output_left_open);
        // A process that leaves the group (its own session) and holds the pipes open delays
        // the run by the drain grace at most.
        let start = Instant::now();
        let out = run(
            &sh("setsid sleep 6 & sleep 0.5; exit 0"),
            &[],
            Duration::from_secs(20),
        )
        .unwrap();
        assert!(matches!(out.ended, Ended::Status(s) if s.success()));
        assert!(out.output_left_open);
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "{:?}",
            start.elapsed()
        );
        // The environment carries the paths.
        let out = run(
            &sh("printf %s \"$STREAKS_OUT\""),
            &[(ENV_OUT, OsStr::new("/w/{out}'x"))],
            Duration::from_secs(20),
        )
        .unwrap();
        assert_eq!(out.stdout.bytes, b"/w/{out}'x");
    }
}
