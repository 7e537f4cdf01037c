//! The stable fuzz runner (no nightly, no libFuzzer), the one CI runs.
//!
//! For each target ([`streaks_fuzz::targets::TARGETS`]) it starts a child process (this
//! executable with `--child`) that replays the target's `corpus/`, `regressions/` (and with
//! `--open`, `open/`) inputs, then mutates the corpus ([`streaks_fuzz::mutate`]) for
//! `--seconds`. Inside the child each input runs under `catch_unwind`, with a watchdog thread
//! (an input running longer than `--timeout` is a hang), a cap on the heap memory live at
//! once (`--memory-mib`, by the global allocator: a larger allocation fails, which aborts) and
//! an address-space limit (RLIMIT_AS) as a backstop for memory the allocator does not see.
//! Before each input the child writes it to its scratch folder, so when the child dies (abort,
//! signal, hang) the parent saves it, and starts a new child that goes on with the replay after
//! that input and then mutates for the rest of the time. Every finding goes to `artifacts/<target>/` with a text
//! file giving the reason and the command that reproduces it; the runner then exits with
//! status 1.
//!
//! An input whose outcome (the reader's error message without its numbers and quoted parts)
//! is new joins the corpus for the rest of the run: a cheap stand-in for coverage feedback.

use clap::Parser;
use sha2::{Digest, Sha256};
use std::alloc::{GlobalAlloc, Layout, System};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use streaks_fuzz::mutate::Mutator;
use streaks_fuzz::targets::{self, Target};
use streaks_fuzz::{files, fuzz_dir, seeds};

/// The child's exit status when its watchdog caught a hang.
const HANG_EXIT: i32 = 71;
/// The child's exit status when it found (and saved) crashes.
const FOUND_EXIT: i32 = 1;
/// How often a dead child is started again (on the rest of its time) before the runner gives
/// up on that target.
const MAX_RESTARTS: u32 = 5;
/// Inputs kept in memory per target.
const MAX_CORPUS: usize = 2000;

/// Fuzz the project's readers on the stable toolchain, in bounded time and memory.
#[derive(Parser)]
#[command(name = "streaks-fuzz")]
struct Args {
    /// Targets to run (`--list` names them).
    targets: Vec<String>,
    /// Run every target.
    #[arg(long)]
    all: bool,
    /// List the targets and exit.
    #[arg(long)]
    list: bool,
    /// Seconds of mutation per target, after its corpus and regressions (0: replay only).
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Seed of the mutations (a run is reproducible from it, up to timing).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Targets fuzzed at once (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Seconds one input may take before it is reported as a hang.
    #[arg(long, default_value_t = 2.0)]
    timeout: f64,
    /// MiB of heap that may be live at once in a target's process; a larger allocation is
    /// reported as an allocation bomb.
    #[arg(long, default_value_t = 1024)]
    memory_mib: usize,
    /// Run only these files, once each, through the one target named (a reproduction).
    #[arg(long, num_args = 1..)]
    replay: Vec<PathBuf>,
    /// Also replay `open/<target>/`: findings not fixed yet.
    #[arg(long)]
    open: bool,
    /// Print the outcome of every replayed input.
    #[arg(long, short)]
    verbose: bool,
    /// Write the seed corpus into `corpus/` and exit.
    #[arg(long)]
    write_seeds: bool,
    /// Shrink FILE, keeping its failure (the same panic place, or an abort or hang), for the
    /// one target named; writes FILE.min.
    #[arg(long, value_name = "FILE")]
    minimize: Option<PathBuf>,
    /// Seconds the minimisation may take.
    #[arg(long, default_value_t = 120.0)]
    minimize_seconds: f64,
    /// Print the folder DIR as one multi-file input whose main file is MAIN, and exit.
    #[arg(long, num_args = 2, value_names = ["DIR", "MAIN"])]
    pack: Vec<PathBuf>,
    /// Internal: run the target named in this process (the parent's child).
    #[arg(long, hide = true)]
    child: Option<String>,
    /// Internal: the child's scratch folder.
    #[arg(long, hide = true)]
    scratch: Option<PathBuf>,
    /// Internal: the child skips this many inputs of its replay (a restart after the input
    /// before them ended the last child).
    #[arg(long, hide = true, default_value_t = 0)]
    skip_replay: usize,
    /// Internal: the child saves no artifacts (minimisation trials).
    #[arg(long, hide = true)]
    no_save: bool,
}

fn main() {
    let args = Args::parse();
    let code = match run(args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("streaks-fuzz: {e}");
            2
        }
    };
    std::process::exit(code);
}

/// Runs the command; the exit status.
fn run(args: Args) -> Result<i32, String> {
    if args.list {
        for t in targets::TARGETS {
            println!("{}", t.name);
        }
        return Ok(0);
    }
    if args.write_seeds {
        let dir = fuzz_dir();
        let repo = dir.parent().ok_or("no repository")?;
        seeds::write_seeds(repo, &dir.join("corpus")).map_err(|e| e.to_string())?;
        return Ok(0);
    }
    if let [dir, main] = args.pack.as_slice() {
        let data = files::pack(dir, &main.to_string_lossy())
            .map_err(|e| format!("cannot pack {}: {e}", dir.display()))?;
        use std::io::Write;
        std::io::stdout()
            .write_all(&data)
            .map_err(|e| e.to_string())?;
        return Ok(0);
    }
    if let Some(name) = &args.child {
        let target = targets::find(name).ok_or_else(|| format!("no target {name}"))?;
        return child(&args, target);
    }
    let chosen: Vec<&'static Target> = if args.all {
        targets::TARGETS.iter().collect()
    } else {
        args.targets
            .iter()
            .map(|n| {
                targets::find(n)
                    .ok_or_else(|| format!("no target {n} (the targets: {})", names().join(", ")))
            })
            .collect::<Result<_, _>>()?
    };
    if chosen.is_empty() {
        return Err(format!(
            "name targets or pass --all (the targets: {})",
            names().join(", ")
        ));
    }
    if (!args.replay.is_empty() || args.minimize.is_some()) && chosen.len() != 1 {
        return Err("--replay and --minimize need exactly one target".into());
    }
    if let Some(path) = &args.minimize {
        return minimize(&args, chosen[0], path);
    }
    if !(args.seconds.is_finite() && args.seconds >= 0.0 && args.timeout > 0.0) {
        return Err("--seconds and --timeout must be positive numbers".into());
    }
    parent(&args, &chosen)
}

/// The targets' names.
fn names() -> Vec<&'static str> {
    targets::TARGETS.iter().map(|t| t.name).collect()
}

/// A target's findings (the lines describing them), or why it could not run.
type Findings = Result<Vec<String>, String>;

/// Runs each target in a child process, `--jobs` at once; the exit status (1 if anything was
/// found).
fn parent(args: &Args, chosen: &[&'static Target]) -> Result<i32, String> {
    let start = Instant::now();
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .clamp(1, chosen.len());
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(&str, Findings)>> = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(target) = chosen.get(i) else { break };
                let result = supervise(args, target);
                results.lock().expect("results").push((target.name, result));
            });
        }
    });
    let results = results.into_inner().expect("results");
    let mut code = 0;
    println!("fuzz: summary ({:.0} s)", start.elapsed().as_secs_f64());
    for target in chosen {
        let Some((_, result)) = results.iter().find(|(n, _)| *n == target.name) else {
            continue;
        };
        match result {
            Ok(found) if found.is_empty() => println!("  ok     {}", target.name),
            Ok(found) => {
                code = 1;
                for f in found {
                    println!("  FOUND  {}: {f}", target.name);
                }
            }
            Err(e) => {
                code = 1;
                println!("  ERROR  {}: {e}", target.name);
            }
        }
    }
    Ok(code)
}

/// Runs one target's child until its time is used, restarting it after a death; the
/// findings (saved artifacts).
fn supervise(args: &Args, target: &Target) -> Findings {
    let scratch = tempfile::Builder::new()
        .prefix(&format!("streaks-fuzz-{}-", target.name))
        .tempdir()
        .map_err(|e| format!("cannot make a scratch folder: {e}"))?;
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this executable: {e}"))?;
    let deadline = Instant::now() + Duration::from_secs_f64(args.seconds);
    let mut found: Vec<String> = Vec::new();
    for restart in 0..=MAX_RESTARTS {
        let current = scratch.path().join("current");
        let _ = std::fs::remove_file(&current);
        let log = scratch.path().join("stderr");
        let seconds = if restart == 0 {
            args.seconds
        } else {
            deadline
                .saturating_duration_since(Instant::now())
                .as_secs_f64()
        };
        let mut cmd = Command::new(&exe);
        // The targets' own scratch folders go inside this one, which is removed at the end.
        cmd.env("TMPDIR", scratch.path());
        cmd.arg("--child")
            .arg(target.name)
            .arg("--scratch")
            .arg(scratch.path())
            .arg("--seconds")
            .arg(seconds.to_string())
            .arg("--seed")
            .arg(args.seed.wrapping_add(u64::from(restart)).to_string())
            .arg("--timeout")
            .arg(args.timeout.to_string())
            .arg("--memory-mib")
            .arg(args.memory_mib.to_string());
        // The replay goes on after the input that ended the last child (a finding must not
        // hide the regressions after it).
        let skip = std::fs::read_to_string(scratch.path().join("replaying"))
            .ok()
            .and_then(|n| n.trim().parse::<usize>().ok())
            .map_or(0, |n| n + 1);
        cmd.arg("--skip-replay").arg(skip.to_string());
        if args.open {
            cmd.arg("--open");
        }
        if args.verbose {
            cmd.arg("--verbose");
        }
        if !args.replay.is_empty() {
            cmd.arg("--replay").args(&args.replay);
        }
        let stderr = std::fs::File::create(&log).map_err(|e| e.to_string())?;
        let mut child = cmd
            .stdin(Stdio::null())
            .stderr(stderr)
            .spawn()
            .map_err(|e| format!("cannot start {}: {e}", exe.display()))?;
        // The watchdog ends hangs; this is for a child that cannot even do that.
        let limit = Duration::from_secs_f64(seconds + 120.0 + 2.0 * args.timeout);
        let started = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
                break Some(status);
            }
            if started.elapsed() > limit {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let errors = std::fs::read_to_string(&log).unwrap_or_default();
        // A restarted child finds the same panics again: one line per place.
        for line in errors.lines().filter_map(|l| l.strip_prefix("found: ")) {
            if !found.iter().any(|f| finding_key(f) == finding_key(line)) {
                found.push(line.to_owned());
            }
        }
        let oom = errors
            .lines()
            .position(|l| l.contains("memory allocation of"));
        let last_panic = errors.lines().rev().find(|l| l.starts_with("panic: "));
        let (kind, reason) = match status {
            Some(s) if s.success() || s.code() == Some(FOUND_EXIT) => break,
            Some(s) if s.code() == Some(HANG_EXIT) => ("hang", last_lines(&errors)),
            Some(s) if oom.is_some() => {
                // The allocation's backtrace, if RUST_BACKTRACE asks for one: its first frames.
                let lines: Vec<&str> = errors.lines().skip(oom.unwrap_or_default()).collect();
                (
                    "oom",
                    format!(
                        "{} ({}, over the {} MiB limit)\n{}",
                        lines[0],
                        describe(s),
                        args.memory_mib,
                        lines[1..lines.len().min(60)].join("\n")
                    ),
                )
            }
            Some(s) => (
                "crash",
                format!(
                    "{}{}\n{}",
                    last_panic.map_or(String::new(), |p| format!("{p}; then ")),
                    describe(s),
                    last_lines(&errors)
                ),
            ),
            None => (
                "hang",
                format!("the child did not end within {} s", limit.as_secs()),
            ),
        };
        let Ok(data) = std::fs::read(&current) else {
            return Err(format!(
                "the child died before running an input ({kind}):\n{reason}"
            ));
        };
        let path = save_artifact(target.name, kind, &data, &reason);
        let line = format!("{kind} ({}): {}", first_line(&reason), path.display());
        println!("fuzz: {}: {line}", target.name);
        found.push(line);
        let replayed = scratch.path().join("replay-done").exists();
        if replayed && Instant::now() >= deadline {
            break;
        }
    }
    Ok(found)
}

/// What tells a finding's line apart from another's: the places of the panics it names (the
/// target's, and the `streaks` command's for the dataset target), or the whole line.
fn finding_key(line: &str) -> String {
    let places: Vec<&str> = line
        .split("panicked at ")
        .skip(1)
        .map(|rest| rest.split(": ").next().unwrap_or(rest))
        .collect();
    if places.is_empty() {
        line.to_owned()
    } else {
        places.join(" ")
    }
}

/// An exit status in words (the signal, if one ended the process).
fn describe(status: ExitStatus) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(signal) = status.signal() {
            return format!("killed by signal {signal}");
        }
    }
    format!("exited with {status}")
}

/// The last 30 lines of `text` but the findings and panics the child listed.
fn last_lines(text: &str) -> String {
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with("found: ") && !l.starts_with("panic: "))
        .collect();
    lines[lines.len().saturating_sub(30)..].join("\n")
}

/// The first non-empty line of `text`, at most 160 characters.
fn first_line(text: &str) -> String {
    let line = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    line.chars().take(160).collect()
}

/// Saves a finding as `artifacts/<target>/<kind>-<hash>` with a `.txt` beside it giving the
/// reason and how to reproduce it; its path.
fn save_artifact(target: &str, kind: &str, data: &[u8], reason: &str) -> PathBuf {
    let hash: String = Sha256::digest(data)[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let dir = fuzz_dir().join("artifacts").join(target);
    let path = dir.join(format!("{kind}-{hash}"));
    let note = format!(
        "{kind} in target {target}:\n{reason}\n\nReproduce:\n  \
         cargo run -p streaks-fuzz -- {target} --replay {path}\n  \
         cargo +nightly fuzz run {target} {path}\n",
        path = path.display()
    );
    let written = std::fs::create_dir_all(&dir)
        .and_then(|()| std::fs::write(&path, data))
        .and_then(|()| std::fs::write(path.with_extension("txt"), note));
    if let Err(e) = written {
        eprintln!("cannot save {}: {e}", path.display());
    }
    path
}

/// The global allocator: the system's, refusing an allocation that would bring the heap live
/// at once above [`MEMORY_LIMIT`] bytes (then Rust aborts with "memory allocation of N bytes
/// failed", which the parent reports as an allocation bomb; `try_reserve` sees an error).
struct Limited;

/// Heap bytes live now.
static LIVE: AtomicUsize = AtomicUsize::new(0);
/// The most heap bytes live at once (no limit until the child sets one).
static MEMORY_LIMIT: AtomicUsize = AtomicUsize::new(usize::MAX);

/// Counts `n` more bytes, unless that passes the limit.
fn reserve(n: usize) -> bool {
    let before = LIVE.fetch_add(n, Ordering::Relaxed);
    if before.saturating_add(n) > MEMORY_LIMIT.load(Ordering::Relaxed) {
        LIVE.fetch_sub(n, Ordering::Relaxed);
        false
    } else {
        true
    }
}

// SAFETY: every call is forwarded to `System` with the same arguments; only the count of live
// bytes is kept beside it, and a refused allocation returns null as `GlobalAlloc` allows.
unsafe impl GlobalAlloc for Limited {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !reserve(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded as received.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if !reserve(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded as received.
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded as received.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let old = layout.size();
        if new_size > old && !reserve(new_size - old) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded as received.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            if new_size > old {
                LIVE.fetch_sub(new_size - old, Ordering::Relaxed);
            }
        } else if new_size < old {
            LIVE.fetch_sub(old - new_size, Ordering::Relaxed);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Limited = Limited;

/// Caps this process's heap at `mib` MiB ([`Limited`]) and its address space at that plus
/// 2 GiB (threads' stacks, code, C libraries' own allocations); processes it starts inherit
/// the address-space limit.
fn limit_memory(mib: usize) {
    let bytes = mib.saturating_mul(1 << 20);
    MEMORY_LIMIT.store(bytes, Ordering::Relaxed);
    #[cfg(unix)]
    {
        let address_space = (bytes as u64).saturating_add(2 << 30) as libc::rlim_t;
        let limit = libc::rlimit {
            rlim_cur: address_space,
            rlim_max: address_space,
        };
        // SAFETY: setrlimit reads the struct it is given and changes only this process.
        if unsafe { libc::setrlimit(libc::RLIMIT_AS, &limit) } != 0 {
            eprintln!(
                "streaks-fuzz: cannot limit the address space: {}",
                std::io::Error::last_os_error()
            );
        }
    }
}

/// The message and place of the last panic (set by the panic hook, taken after `catch_unwind`).
static LAST_PANIC: Mutex<Option<(String, String)>> = Mutex::new(None);
/// When the input now running started (`None` between inputs), for the watchdog.
static RUNNING_SINCE: Mutex<Option<Instant>> = Mutex::new(None);

/// The child: replays the corpus, then mutates it until the time is up; exits 0, or
/// [`FOUND_EXIT`] after saving crashes; the watchdog exits with [`HANG_EXIT`].
fn child(args: &Args, target: &Target) -> Result<i32, String> {
    limit_memory(args.memory_mib);
    let scratch = args.scratch.clone().ok_or("--child needs --scratch")?;
    let current = scratch.join("current");
    std::panic::set_hook(Box::new(|info| {
        let place = info
            .location()
            .map_or_else(|| "unknown place".to_owned(), |l| l.to_string());
        let payload = info.payload();
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic".to_owned());
        // Also on stderr, for the parent: a panic where nothing catches it (a thread pool's
        // task) aborts the process.
        eprintln!("panic: {place}: {}", first_line(&message));
        if let Ok(mut last) = LAST_PANIC.lock() {
            *last = Some((place, message));
        }
    }));
    let timeout = Duration::from_secs_f64(args.timeout);
    std::thread::spawn(move || loop {
        std::thread::sleep(Duration::from_millis(50));
        let since = *RUNNING_SINCE.lock().unwrap_or_else(|e| e.into_inner());
        if since.is_some_and(|s| s.elapsed() > timeout) {
            eprintln!("hang: an input ran longer than {timeout:?}");
            std::process::exit(HANG_EXIT);
        }
    });

    let mut seeds: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if args.replay.is_empty() {
        let mut folders = vec!["corpus", "regressions"];
        if args.open {
            folders.push("open");
        }
        for folder in folders {
            seeds.extend(read_folder(&fuzz_dir().join(folder).join(target.name))?);
        }
    } else {
        for path in &args.replay {
            let data =
                std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
            seeds.push((path.clone(), data));
        }
    }

    let mut run = Runner {
        target,
        current,
        kinds: HashSet::new(),
        places: HashSet::new(),
        found: Vec::new(),
        executed: 0,
        save: !args.no_save,
    };
    let mut corpus: Vec<Vec<u8>> = Vec::new();
    let replaying = scratch.join("replaying");
    for (i, (path, data)) in seeds.into_iter().enumerate() {
        if i >= args.skip_replay {
            // For the parent: where to go on if this input ends the process.
            if let Err(e) = std::fs::write(&replaying, i.to_string()) {
                eprintln!("cannot write {}: {e}", replaying.display());
            }
            let (outcome, _) = run.input(&data);
            if args.verbose || !args.replay.is_empty() {
                let what = match &outcome {
                    Some(Ok(())) => "read".to_owned(),
                    Some(Err(e)) => format!("error: {}", first_line(e)),
                    None => "PANIC".to_owned(),
                };
                println!("fuzz: {}: {}: {what}", target.name, path.display());
            }
        }
        corpus.push(data);
    }
    let replayed = run.executed;
    if let Err(e) = std::fs::write(scratch.join("replay-done"), "") {
        eprintln!("cannot write {}: {e}", scratch.display());
    }
    if corpus.is_empty() {
        corpus.push(Vec::new());
    }

    let start = Instant::now();
    let budget = if args.replay.is_empty() {
        Duration::from_secs_f64(args.seconds)
    } else {
        Duration::ZERO
    };
    let mut mutator = Mutator::new(args.seed ^ hash_name(target.name));
    while start.elapsed() < budget {
        let base = &corpus[mutator.below(corpus.len())];
        let other = &corpus[mutator.below(corpus.len())];
        let mutant = mutator.mutate(base, other, target.multi_file, target.dictionary);
        let (_, new) = run.input(&mutant);
        if new && corpus.len() < MAX_CORPUS {
            corpus.push(mutant);
        }
    }
    println!(
        "fuzz: {}: {} inputs ({replayed} replayed) in {:.1} s, {} outcome kinds, corpus {}, {} found",
        target.name,
        run.executed,
        start.elapsed().as_secs_f64(),
        run.kinds.len(),
        corpus.len(),
        run.found.len()
    );
    Ok(if run.found.is_empty() { 0 } else { FOUND_EXIT })
}

/// A stable hash of a target's name, so that targets mutate differently from one seed.
fn hash_name(name: &str) -> u64 {
    let digest = Sha256::digest(name.as_bytes());
    u64::from_le_bytes(digest[..8].try_into().expect("8 bytes"))
}

/// The files of `dir` (none if it does not exist), sorted by name.
fn read_folder(dir: &Path) -> Result<Vec<(PathBuf, Vec<u8>)>, String> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("cannot list {}: {e}", dir.display())),
    };
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.extension().is_none_or(|e| e != "txt"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            std::fs::read(&p)
                .map(|d| (p.clone(), d))
                .map_err(|e| format!("cannot read {}: {e}", p.display()))
        })
        .collect()
}

/// Runs inputs through a target in the child, keeping what came of them.
struct Runner<'a> {
    target: &'a Target,
    /// Where each input is written before it runs (the parent saves it if the child dies).
    current: PathBuf,
    /// The outcome kinds seen.
    kinds: HashSet<String>,
    /// The places of the panics found.
    places: HashSet<String>,
    /// The findings, as lines for the parent.
    found: Vec<String>,
    /// Inputs run.
    executed: u64,
    /// Whether findings are saved as artifacts.
    save: bool,
}

impl Runner<'_> {
    /// Runs one input: its outcome (`None` for a panic) and whether the outcome is of a new
    /// kind.
    fn input(&mut self, data: &[u8]) -> (Option<targets::Outcome>, bool) {
        if let Err(e) = std::fs::write(&self.current, data) {
            eprintln!("cannot write {}: {e}", self.current.display());
        }
        self.executed += 1;
        *RUNNING_SINCE.lock().unwrap_or_else(|e| e.into_inner()) = Some(Instant::now());
        let run = self.target.run;
        let result = std::panic::catch_unwind(|| run(data));
        *RUNNING_SINCE.lock().unwrap_or_else(|e| e.into_inner()) = None;
        match result {
            Ok(outcome) => {
                let kind = match &outcome {
                    Ok(()) => "ok".to_owned(),
                    Err(e) => kind_of(&first_line(e)),
                };
                (Some(outcome), self.kinds.insert(kind))
            }
            Err(_) => {
                let (place, message) = LAST_PANIC
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .take()
                    .unwrap_or_else(|| ("unknown place".into(), "a panic".into()));
                // One finding per place (the dataset target's panics all come from one place,
                // its message names the command's own).
                let key = finding_key(&format!("panicked at {place}: {message}"));
                if self.places.insert(key) {
                    let reason = format!("panicked at {place}:\n{message}");
                    let path = if self.save {
                        save_artifact(self.target.name, "crash", data, &reason)
                    } else {
                        PathBuf::new()
                    };
                    let line = format!(
                        "crash (panicked at {place}: {}): {}",
                        first_line(&message),
                        path.display()
                    );
                    println!("fuzz: {}: {line}", self.target.name);
                    // Now, not at the end: the parent reads these even if this process dies.
                    eprintln!("found: {line}");
                    self.found.push(line);
                }
                (None, false)
            }
        }
    }
}

/// An error message without what varies with the input: what follows its first quote (a
/// name or a value from the input), its digits, and anything past 160 characters.
fn kind_of(message: &str) -> String {
    let mut kind = String::new();
    for c in message.chars() {
        if matches!(c, '"' | '`' | '\'') || kind.len() >= 160 {
            break;
        }
        if !c.is_ascii_digit() {
            kind.push(c);
        } else if !kind.ends_with('#') {
            kind.push('#');
        }
    }
    kind
}

/// How an input fails: `crash at PLACE`, `oom`, `hang`, or `None` when it does not.
fn failure(
    exe: &Path,
    args: &Args,
    target: &Target,
    scratch: &Path,
    data: &[u8],
) -> Option<String> {
    let input = scratch.join("input");
    std::fs::write(&input, data).ok()?;
    let out = Command::new(exe)
        .env("TMPDIR", scratch)
        .arg("--child")
        .arg(target.name)
        .arg("--scratch")
        .arg(scratch)
        .args(["--no-save", "--replay"])
        .arg(&input)
        .arg("--timeout")
        .arg(args.timeout.to_string())
        .arg("--memory-mib")
        .arg(args.memory_mib.to_string())
        .stdin(Stdio::null())
        .output()
        .ok()?;
    let errors = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        return None;
    }
    if out.status.code() == Some(HANG_EXIT) {
        return Some("hang".into());
    }
    if errors.contains("memory allocation of") {
        return Some("oom".into());
    }
    let place = errors
        .lines()
        .find_map(|l| l.split("panicked at ").nth(1))
        .and_then(|rest| rest.split(": ").next())
        .unwrap_or("an abort");
    Some(format!("crash at {place}"))
}

/// Shrinks the input at `path` while it fails as it does ([`failure`]): drops the extra
/// files of a multi-file input one by one, then ranges of bytes from half a file down to one
/// byte; writes the result beside it as `<path>.min`.
fn minimize(args: &Args, target: &Target, path: &Path) -> Result<i32, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this executable: {e}"))?;
    let scratch = tempfile::tempdir().map_err(|e| e.to_string())?;
    let mut best =
        std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let Some(goal) = failure(&exe, args, target, scratch.path(), &best) else {
        return Err(format!(
            "{} does not fail in target {}",
            path.display(),
            target.name
        ));
    };
    println!(
        "fuzz: minimising {} ({} bytes, {goal})",
        path.display(),
        best.len()
    );
    let deadline = Instant::now() + Duration::from_secs_f64(args.minimize_seconds);
    let keeps = |candidate: &[u8]| {
        Instant::now() < deadline
            && failure(&exe, args, target, scratch.path(), candidate).as_ref() == Some(&goal)
    };
    let mut parts = if target.multi_file {
        files::split(&best)
    } else {
        vec![files::Part {
            name: None,
            bytes: best.clone(),
        }]
    };
    let joined = |parts: &[files::Part]| {
        if target.multi_file {
            files::join(parts)
        } else {
            parts[0].bytes.clone()
        }
    };
    let mut i = 1;
    while i < parts.len() {
        let mut fewer = parts.clone();
        fewer.remove(i);
        if keeps(&joined(&fewer)) {
            parts = fewer;
        } else {
            i += 1;
        }
    }
    for p in 0..parts.len() {
        let mut chunk = parts[p].bytes.len().div_ceil(2).max(1);
        loop {
            let mut at = 0;
            while at < parts[p].bytes.len() {
                let mut shorter = parts.clone();
                let end = (at + chunk).min(shorter[p].bytes.len());
                shorter[p].bytes.drain(at..end);
                if keeps(&joined(&shorter)) {
                    parts = shorter;
                } else {
                    at += chunk;
                }
            }
            if chunk == 1 {
                break;
            }
            chunk = chunk.div_ceil(2);
        }
    }
    best = joined(&parts);
    let out = PathBuf::from(format!("{}.min", path.display()));
    std::fs::write(&out, &best).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    println!("fuzz: {} ({} bytes, {goal})", out.display(), best.len());
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn findings_are_told_apart_by_their_panics_places() {
        let a = "crash (panicked at x.rs:1:2: unwrap on [0.5]): artifacts/obj/crash-1";
        let b = "crash (panicked at x.rs:1:2: unwrap on [1.0, 2.0]): artifacts/obj/crash-2";
        assert_eq!(finding_key(a), finding_key(b));
        let c = "crash (panicked at t.rs:4:1: streaks dataset index panicked at i.rs:9:9: x): p";
        let d = "crash (panicked at t.rs:4:1: streaks dataset index panicked at i.rs:7:7: x): p";
        assert_eq!(finding_key(c), "t.rs:4:1 i.rs:9:9");
        assert_ne!(finding_key(c), finding_key(d));
    }

    #[test]
    fn kinds_leave_out_numbers_and_quoted_parts() {
        assert_eq!(
            kind_of("truncated data: 42 bytes for 7x3, expected 84"),
            "truncated data: # bytes for #x#, expected #"
        );
        assert_eq!(
            kind_of("unknown key \"xyz\" at line 3"),
            kind_of("unknown key \"abc\" at line 12")
        );
    }
}
