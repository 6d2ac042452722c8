//! The long fuzzing run over every loader (see `tests/fuzz_support/mod.rs` for the approach and
//! docs/testing.md for the figures):
//!
//!     cargo run --release --example fuzz -- --execs 1000000 --loader species
//!
//! `--loader` is one of species, script, scenario, asc, pgm, features, http, or `all` (the
//! default); `--seed` (default 1) makes another deterministic run; inputs that panic, hang (over
//! 5 s) or abort the process are written to `--crashes` (default `fuzz-crashes/`);
//! `--loader NAME --replay FILE` runs one saved input and prints its outcome and time. Each loader
//! runs in a child process, so that an abort (a stack overflow, a failed allocation) is reported
//! and its input recovered by replaying the run up to it, instead of ending the whole run.

#[path = "../tests/fuzz_support/mod.rs"]
mod fuzz_support;

use fuzz_support::Target;
use std::path::PathBuf;
use std::process::{Command, ExitCode};

struct Args {
    execs: u64,
    loaders: Vec<Target>,
    seed: u64,
    crashes: PathBuf,
    worker: bool,
    dump_from: Option<u64>,
    replay: Option<PathBuf>,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        execs: 100_000,
        loaders: Target::ALL.to_vec(),
        seed: 1,
        crashes: PathBuf::from("fuzz-crashes"),
        worker: false,
        dump_from: None,
        replay: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let mut val = || it.next().ok_or(format!("{k} needs a value"));
        match k.as_str() {
            "--execs" => a.execs = val()?.parse().map_err(|e| format!("--execs: {e}"))?,
            "--seed" => a.seed = val()?.parse().map_err(|e| format!("--seed: {e}"))?,
            "--crashes" => a.crashes = PathBuf::from(val()?),
            "--dump-from" => {
                a.dump_from = Some(val()?.parse().map_err(|e| format!("--dump-from: {e}"))?)
            }
            "--worker" => a.worker = true,
            "--replay" => a.replay = Some(PathBuf::from(val()?)),
            "--loader" => {
                let v = val()?;
                a.loaders = if v == "all" {
                    Target::ALL.to_vec()
                } else {
                    v.split(',')
                        .map(|n| Target::parse(n).ok_or(format!("unknown loader {n}")))
                        .collect::<Result<_, _>>()?
                };
            }
            _ => return Err(format!("unknown argument {k}")),
        }
    }
    Ok(a)
}

/// Runs one loader in this process; the exit code says whether it found anything.
fn worker(a: &Args) -> ExitCode {
    let t = a.loaders[0];
    let dump = a
        .dump_from
        .map(|n| (n, a.crashes.join(format!("{}-abort.bin", t.name()))));
    if dump.is_some() {
        std::fs::create_dir_all(&a.crashes).unwrap();
    }
    let rep = fuzz_support::run(t, a.seed, a.execs, 10, dump, |r| {
        eprintln!("  … {r}");
    });
    println!("{rep}");
    if let Some((shape, input)) = &rep.unlocated_example {
        println!(
            "  unlocated refusal, e.g. \"{shape}\" for {:?}",
            String::from_utf8_lossy(&input[..input.len().min(200)])
        );
    }
    for (f, p) in rep
        .findings
        .iter()
        .zip(fuzz_support::save_findings(&rep, &a.crashes))
    {
        println!(
            "  {} at exec {}: {} -> {}",
            f.kind,
            f.exec,
            f.message,
            p.display()
        );
    }
    if rep.findings.is_empty() {
        ExitCode::SUCCESS
    } else {
        // A hung worker thread would keep the process alive.
        std::process::exit(1)
    }
}

fn main() -> ExitCode {
    let a = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("fuzz: {e}");
            return ExitCode::from(2);
        }
    };
    if let Some(file) = &a.replay {
        // One saved input, on the first loader named: its outcome and time.
        let input = std::fs::read(file).unwrap();
        let start = std::time::Instant::now();
        let outcome = fuzz_support::execute(a.loaders[0], &input);
        println!(
            "{outcome:?} in {:.1} ms",
            start.elapsed().as_secs_f64() * 1e3
        );
        return ExitCode::SUCCESS;
    }
    if a.worker {
        return worker(&a);
    }
    let me = std::env::current_exe().unwrap();
    let mut failed = false;
    for t in &a.loaders {
        let base = |cmd: &mut Command| {
            cmd.args(["--worker", "--loader", t.name()])
                .args(["--execs", &a.execs.to_string()])
                .args(["--seed", &a.seed.to_string()])
                .arg("--crashes")
                .arg(&a.crashes);
        };
        let mut cmd = Command::new(&me);
        base(&mut cmd);
        let out = cmd.stderr(std::process::Stdio::piped()).output().unwrap();
        print!("{}", String::from_utf8_lossy(&out.stdout));
        if out.status.success() {
            continue;
        }
        failed = true;
        if out.status.code() == Some(1) {
            continue;
        }
        // Killed by a signal: the progress lines say roughly where; replay to dump the input.
        let err = String::from_utf8_lossy(&out.stderr);
        println!(
            "{} aborted ({}): {}",
            t.name(),
            out.status,
            err.lines().last().unwrap_or("")
        );
        let last = err
            .lines()
            .rev()
            .find_map(|l| l.split_whitespace().nth(2)?.parse::<u64>().ok())
            .unwrap_or(0);
        let mut cmd = Command::new(&me);
        base(&mut cmd);
        cmd.args(["--dump-from", &last.to_string()]);
        let st = cmd.output().unwrap().status;
        let p = a.crashes.join(format!("{}-abort.bin", t.name()));
        if st.code().is_none() {
            println!("  abort input: {}", p.display());
        } else {
            println!("  the replay did not abort ({st}); the input was not recovered");
        }
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
