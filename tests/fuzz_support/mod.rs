//! An in-process mutation fuzzer over every loader of user files (species, script, scenario,
//! ESRI and PGM terrain, features) and the live server's HTTP request parser, shared by the
//! short run in `tests/fuzz_loaders.rs` and the long run in `examples/fuzz.rs`.
//!
//! Why not `cargo afl` or cargo-fuzz: cargo-fuzz (libFuzzer) needs a nightly toolchain, and
//! `cargo afl` needs AFL++ built from source and a fork server per target, which does not fit the
//! stable-only, offline, 2-core CI. So this is a deterministic mutator on the stable toolchain:
//! the seed corpus is every shipped file a loader reads; mutations are byte flips, token swaps
//! and insertions from a dictionary of the corpus's own words, hostile numbers (NaN, inf, -0,
//! 1e39, 2^31, 2^64...), huge repeats, deep nesting, truncation and splicing of two files. It is
//! not coverage-guided (that needs instrumentation); instead it is outcome-guided: an input whose
//! result (accepted, or the shape of its first diagnostic) was never seen joins the corpus, so
//! the fuzzer keeps inputs that reach new checks. Each execution runs under `catch_unwind` and a
//! watchdog thread that calls an input taking over 5 s a hang.

#![allow(dead_code)]

use std::collections::HashSet;
use std::fmt;
use std::io::BufReader;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use shoal::diag::Diagnostic;
use shoal::live::http::{self, read_request};
use shoal::scenario::{script_limits, Scenario};
use shoal::script::Script;
use shoal::species::load_species_str;
use shoal::terrain::{parse_asc, parse_pgm, Features, Terrain};

/// An input that runs longer than this is a hang.
pub const HANG: Duration = Duration::from_secs(5);

/// Largest input the mutator builds: big enough for repeats to reach the loaders' size limits.
const MAX_INPUT: usize = 1 << 20;

/// Most inputs kept per loader (seeds included).
const MAX_CORPUS: usize = 2000;

/// What is fuzzed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A species file (RON), its script loaded from the shipped behaviors.
    Species,
    /// A species script (Rhai), imports resolved in the shipped behaviors.
    Script,
    /// A scenario (RON), species and terrain loaded from the shipped files.
    Scenario,
    /// An ESRI ASCII grid.
    Asc,
    /// A binary PGM height map.
    Pgm,
    /// A terrain feature file (RON), parsed and applied to the shipped valley.
    Features,
    /// One HTTP request as the live server reads it, then its `/control` body.
    Http,
}

impl Target {
    /// Every target, in the order the runs report them.
    pub const ALL: [Target; 7] = [
        Target::Species,
        Target::Script,
        Target::Scenario,
        Target::Asc,
        Target::Pgm,
        Target::Features,
        Target::Http,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Target::Species => "species",
            Target::Script => "script",
            Target::Scenario => "scenario",
            Target::Asc => "asc",
            Target::Pgm => "pgm",
            Target::Features => "features",
            Target::Http => "http",
        }
    }

    /// The target named `s`.
    pub fn parse(s: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == s)
    }
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn files_under(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = rd.flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files_under(&p, ext, out);
        } else if p.extension().is_some_and(|e| e == ext) {
            out.push(p);
        }
    }
}

/// A small binary PGM: `maxval` < 256 gives 8-bit samples, else 16-bit.
fn pgm(cols: usize, rows: usize, maxval: u32, comment: bool) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(b"P5\n");
    if comment {
        b.extend_from_slice(b"# written by the fuzz seeds\n");
    }
    b.extend_from_slice(format!("{cols} {rows}\n{maxval}\n").as_bytes());
    for i in 0..cols * rows {
        let v = (i as u32 * 37) % (maxval + 1);
        if maxval < 256 {
            b.push(v as u8);
        } else {
            b.extend_from_slice(&(v as u16).to_be_bytes());
        }
    }
    b
}

/// The seed corpus of `t`: every shipped file that loader reads (built-in samples where the
/// project ships none: PGM height maps and HTTP requests).
pub fn seeds(t: Target) -> Vec<Vec<u8>> {
    let r = root();
    let mut files = Vec::new();
    match t {
        Target::Species => {
            for p in std::fs::read_dir(r.join("behaviors")).unwrap().flatten() {
                if p.path().extension().is_some_and(|e| e == "ron") {
                    files.push(p.path());
                }
            }
            files_under(&r.join("src/bench"), "ron", &mut files);
        }
        Target::Script => files_under(&r.join("behaviors"), "rhai", &mut files),
        Target::Scenario => files_under(&r.join("scenarios"), "ron", &mut files),
        Target::Asc => files_under(&r.join("assets/terrain"), "asc", &mut files),
        Target::Features => files.push(r.join("assets/terrain/valley_features.ron")),
        Target::Pgm => {
            return vec![
                pgm(16, 12, 255, true),
                pgm(8, 8, 65535, false),
                pgm(1, 1, 1, false),
            ];
        }
        Target::Http => {
            return [
                "GET / HTTP/1.1\r\nHost: 127.0.0.1:7878\r\n\r\n",
                "GET /stream HTTP/1.1\r\nHost: localhost:7878\r\nAccept: text/event-stream\r\n\r\n",
                "GET /status?x=1#f HTTP/1.1\r\nHost: [::1]:7878\r\n\r\n",
                "GET /agent/12 HTTP/1.0\r\nhost: 127.0.0.1:7878\r\n\r\n",
                "POST /control HTTP/1.1\r\nHost: 127.0.0.1:7878\r\nOrigin: http://127.0.0.1:7878\r\nContent-Type: application/json\r\nContent-Length: 15\r\n\r\n{\"cmd\":\"pause\"}",
                "POST /control HTTP/1.1\r\nHost: 127.0.0.1:7878\r\nContent-Length: 29\r\n\r\n{\"cmd\":\"speed\",\"value\":2.5}  ",
                "POST /control HTTP/1.1\r\nHost: 127.0.0.1:7878\r\nTransfer-Encoding: chunked\r\n\r\n5\r\nhello\r\n0\r\n\r\n",
                "\r\n\r\nOPTIONS * HTTP/1.1\nHost: evil.example\n\n",
            ]
            .iter()
            .map(|s| s.as_bytes().to_vec())
            .collect();
        }
    }
    files.sort();
    files.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// The result of one execution.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Outcome {
    /// Accepted.
    Ok,
    /// Refused: the shape of the first problem (digits dropped) and whether it has a position.
    Refused { shape: String, located: bool },
}

fn refused(d: &[Diagnostic]) -> Outcome {
    let Some(first) = d.first() else {
        // An error without a diagnostic tells the user nothing: count it as unlocated.
        return Outcome::Refused {
            shape: "empty diagnostics".into(),
            located: false,
        };
    };
    Outcome::Refused {
        shape: shape(&first.message),
        located: d.iter().all(|x| x.line > 0),
    }
}

/// A message without its digits and quoted parts, so that "line 3" and "line 4" are one shape.
/// The checkout's path is dropped first: a message naming a file would otherwise cut at another
/// place in another checkout, and the run (which keeps inputs of new shapes) would differ.
fn shape(msg: &str) -> String {
    let msg = msg.replace(env!("CARGO_MANIFEST_DIR"), "");
    let mut out = String::new();
    let mut quoted = false;
    for ch in msg.chars().take(120) {
        match ch {
            '"' | '`' => {
                quoted = !quoted;
                out.push(ch);
            }
            _ if quoted => {}
            c if c.is_ascii_digit() => {
                if !out.ends_with('#') {
                    out.push('#');
                }
            }
            c => out.push(c),
        }
    }
    out
}

/// Text as the loaders get it: read_text refuses text that is not UTF-8 before a loader sees it.
fn text(input: &[u8]) -> Option<&str> {
    std::str::from_utf8(input).ok()
}

fn valley() -> &'static Terrain {
    static V: OnceLock<Terrain> = OnceLock::new();
    V.get_or_init(|| shoal::terrain::load_asc(&root().join("assets/terrain/valley.asc")).unwrap())
}

/// Runs loader `t` on `input` once.
pub fn execute(t: Target, input: &[u8]) -> Outcome {
    let r = root();
    let Some(s) = text(input).or(if t == Target::Pgm || t == Target::Http {
        Some("")
    } else {
        None
    }) else {
        return Outcome::Refused {
            shape: "not UTF-8".into(),
            located: true,
        };
    };
    let diags = |res: Result<(), shoal::diag::Diagnostics>| match res {
        Ok(()) => Outcome::Ok,
        Err(d) => refused(&d.0),
    };
    match t {
        Target::Species => {
            let behaviors = r.join("behaviors");
            diags(
                load_species_str(
                    &behaviors.join("fuzzed.ron"),
                    s,
                    &behaviors,
                    &script_limits(),
                )
                .map(drop),
            )
        }
        Target::Script => {
            let behaviors = r.join("behaviors");
            diags(
                Script::compile(
                    &behaviors.join("fuzzed.rhai"),
                    s,
                    &behaviors,
                    &script_limits(),
                )
                .map(drop),
            )
        }
        Target::Scenario => diags(Scenario::load_str(&r.join("scenarios/fuzzed.ron"), s).map(drop)),
        Target::Asc => diags(parse_asc(s, "fuzzed.asc").map(drop)),
        Target::Pgm => diags(parse_pgm(input, "fuzzed.pgm", 1.0, 1.0).map(drop)),
        Target::Features => diags(Features::parse(s, "fuzzed.ron").map(|f| {
            let mut v = valley().clone();
            v.apply_features(&f);
        })),
        Target::Http => {
            // The socket delivers a request in pieces: vary where the reads split it.
            let cap = 1 + input
                .iter()
                .fold(0usize, |a, &b| a.wrapping_mul(31) + b as usize)
                % 97;
            let mut reader = BufReader::with_capacity(cap, input);
            match read_request(&mut reader, &http::HttpLimits::default()) {
                Ok(req) => {
                    http::forbidden(&req, 7878);
                    match shoal::live::server::parse_control(&req.body) {
                        Ok(_) => Outcome::Ok,
                        Err(e) => Outcome::Refused {
                            shape: shape(&e),
                            located: true,
                        },
                    }
                }
                Err(e) => Outcome::Refused {
                    shape: format!("{e:?}"),
                    located: true,
                },
            }
        }
    }
}

/// SplitMix64: small, fast and the same on every platform.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (`n` > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// Small numbers far more often than large ones: most edits are local.
    fn small(&mut self, n: usize) -> usize {
        let bits = 1 + self.below(usize::BITS as usize - n.leading_zeros() as usize);
        self.below(n.min(1 << bits).max(1))
    }
}

/// Numbers that break careless code: non-finite, negative zero, past f32, past i32, u32, u64.
const HOSTILE_NUMBERS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "-0",
    "-0.0",
    "0",
    "1e39",
    "-1e39",
    "1e308",
    "1e-45",
    "3.4028235e38",
    "2147483647",
    "2147483648",
    "-2147483649",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "99999999999999999999999999999",
    "65535",
    "65536",
    "1.",
    ".5",
    "1e",
    "-",
    "0x7fffffff",
    "1_000",
];

/// Tokens of each format that the corpus may lack.
fn format_tokens(t: Target) -> &'static [&'static str] {
    match t {
        Target::Species | Target::Scenario | Target::Features => &[
            "(",
            ")",
            "[",
            "]",
            "{",
            "}",
            ":",
            ",",
            "\"",
            "Some(",
            "None",
            "true",
            "false",
            "#![enable(implicit_some)]\n",
            "r#\"",
            "'x'",
            "/*",
            "//",
            "\\u{0}",
            "()",
            "[]",
        ],
        Target::Script => &[
            "fn ",
            "import ",
            " as ",
            "while true {",
            "loop {",
            "eval(",
            "let ",
            "const ",
            "{",
            "}",
            "(",
            ")",
            "[",
            "]",
            "#{",
            "\"",
            "`",
            "${",
            "//",
            "/*",
            ";",
            "return ",
            "this",
            "Fn(",
            ".call(",
            "switch ",
            "=>",
            "..",
            "**",
            "<<",
        ],
        Target::Asc => &[
            "ncols ",
            "nrows ",
            "xllcorner ",
            "yllcenter ",
            "cellsize ",
            "NODATA_value ",
            "\n",
            " ",
            "\t",
            "\r\n",
            "-9999",
        ],
        Target::Pgm => &[
            "P5", "P2", "\n", " ", "#", "255", "256", "65535", "65536", "0", "\0", "\u{ff}",
        ],
        Target::Http => &[
            "\r\n",
            "\n",
            "\r\n\r\n",
            ": ",
            "GET",
            "POST",
            " HTTP/1.1",
            "Host: ",
            "Origin: ",
            "Content-Length: ",
            "Transfer-Encoding: chunked",
            "127.0.0.1:7878",
            "[::1]",
            "localhost.",
            "null",
            "{\"cmd\":",
            "\"step\"",
            "\"speed\"",
            "\"value\":",
            "\"seek\"",
            "1e999",
        ],
    }
}

/// The words and punctuation of `corpus`, deduplicated, in first-seen order.
fn dictionary(t: Target, corpus: &[Vec<u8>]) -> Vec<Vec<u8>> {
    let mut seen = HashSet::new();
    let mut out: Vec<Vec<u8>> = Vec::new();
    let mut push = |w: &[u8], out: &mut Vec<Vec<u8>>| {
        if !w.is_empty() && w.len() <= 40 && seen.insert(w.to_vec()) {
            out.push(w.to_vec());
        }
    };
    for s in HOSTILE_NUMBERS.iter().chain(format_tokens(t)) {
        push(s.as_bytes(), &mut out);
    }
    if t == Target::Pgm {
        return out;
    }
    for f in corpus {
        let mut start = None;
        for (i, &b) in f.iter().enumerate() {
            let word = b.is_ascii_alphanumeric() || b == b'_' || b == b'.';
            match (word, start) {
                (true, None) => start = Some(i),
                (false, Some(s0)) => {
                    push(&f[s0..i], &mut out);
                    start = None;
                }
                _ => {}
            }
            if !word && b.is_ascii_punctuation() {
                push(&f[i..=i], &mut out);
            }
        }
    }
    out
}

/// Byte ranges of the numbers in `input`.
fn numbers(input: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < input.len() {
        let starts = input[i].is_ascii_digit()
            || (input[i] == b'-' && input.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (input[i - 1].is_ascii_alphanumeric() || input[i - 1] == b'_');
        if starts && !after_word {
            let s0 = i;
            i += 1;
            while i < input.len()
                && (input[i].is_ascii_alphanumeric() || matches!(input[i], b'.' | b'_' | b'-'))
            {
                i += 1;
            }
            out.push((s0, i));
        } else {
            i += 1;
        }
    }
    out
}

/// The mutation engine and its corpus for one target.
pub struct Fuzzer {
    target: Target,
    rng: Rng,
    corpus: Vec<Vec<u8>>,
    dict: Vec<Vec<u8>>,
    seen: HashSet<Outcome>,
}

impl Fuzzer {
    /// A fuzzer for `t` seeded with `seed`, its corpus the shipped files.
    pub fn new(t: Target, seed: u64) -> Fuzzer {
        let corpus = seeds(t);
        let dict = dictionary(t, &corpus);
        Fuzzer {
            target: t,
            rng: Rng::new(seed ^ (t as u64).wrapping_mul(0x5851_f42d_4c95_7f2d)),
            corpus,
            dict,
            seen: HashSet::new(),
        }
    }

    /// Inputs in the corpus.
    pub fn corpus_len(&self) -> usize {
        self.corpus.len()
    }

    /// The next input: a seed now and then, else one to four mutations of a corpus entry.
    pub fn next_input(&mut self) -> Vec<u8> {
        let mut input = self.corpus[self.rng.below(self.corpus.len())].clone();
        if self.rng.below(50) == 0 {
            return input;
        }
        for _ in 0..1 + self.rng.small(4) {
            self.mutate(&mut input);
        }
        input.truncate(MAX_INPUT);
        input
    }

    /// Keeps `input` when its outcome is new.
    pub fn observe(&mut self, input: Vec<u8>, outcome: Outcome) {
        if self.seen.insert(outcome) && self.corpus.len() < MAX_CORPUS && input.len() < 1 << 16 {
            self.corpus.push(input);
        }
    }

    fn pos(&mut self, input: &[u8]) -> usize {
        self.rng.below(input.len() + 1)
    }

    fn word(&mut self) -> Vec<u8> {
        self.dict[self.rng.below(self.dict.len())].clone()
    }

    fn mutate(&mut self, input: &mut Vec<u8>) {
        let r = &mut self.rng;
        match r.below(12) {
            // A bit flip.
            0 if !input.is_empty() => {
                let i = r.below(input.len());
                input[i] ^= 1 << r.below(8);
            }
            // A byte from the format's syntax, or any byte.
            1 if !input.is_empty() => {
                let i = r.below(input.len());
                input[i] = *b"()[]{}:,\"'#\\\n\0\xff-. "
                    .get(r.below(24))
                    .unwrap_or(&(r.next() as u8));
            }
            // A deletion.
            2 if !input.is_empty() => {
                let i = r.below(input.len());
                let n = 1 + r.small(input.len() - i);
                input.drain(i..(i + n).min(input.len()));
            }
            // A copy of a range elsewhere.
            3 if !input.is_empty() => {
                let i = r.below(input.len());
                let n = 1 + r.small((input.len() - i).min(256));
                let piece = input[i..(i + n).min(input.len())].to_vec();
                let at = self.pos(input);
                input.splice(at..at, piece);
            }
            // A number replaced by a hostile one.
            4 | 5 => {
                let nums = numbers(input);
                if nums.is_empty() {
                    return self.mutate(input);
                }
                let (a, b) = nums[r.below(nums.len())];
                let n = HOSTILE_NUMBERS[r.below(HOSTILE_NUMBERS.len())];
                input.splice(a..b, n.bytes());
            }
            // A word swapped for another of the dictionary.
            6 => {
                let words = words(input);
                if words.is_empty() {
                    return self.mutate(input);
                }
                let (a, b) = words[r.below(words.len())];
                let w = self.word();
                input.splice(a..b, w);
            }
            // A word inserted.
            7 => {
                let at = self.pos(input);
                let w = self.word();
                input.splice(at..at, w);
            }
            // A huge repeat of a small piece.
            8 if !input.is_empty() => {
                let i = r.below(input.len());
                let n = 1 + r.small((input.len() - i).min(32));
                let piece = input[i..(i + n).min(input.len())].to_vec();
                let times = 1 + r.small(MAX_INPUT / piece.len().max(1));
                let at = self.pos(input);
                input.splice(at..at, piece.repeat(times).into_iter().take(MAX_INPUT));
            }
            // Deep nesting.
            9 => {
                let open = ["(", "[", "{", "#{", "Some(", "-", "!"][r.below(7)];
                let depth = 1 + r.small(100_000);
                let at = self.pos(input);
                input.splice(at..at, open.repeat(depth).into_bytes());
            }
            // Truncation.
            10 if !input.is_empty() => {
                let at = r.below(input.len());
                input.truncate(at);
            }
            // Splice: the head of this input, the tail of another.
            _ => {
                let other = self.corpus[self.rng.below(self.corpus.len())].clone();
                let at = self.pos(input);
                let from = self.rng.below(other.len() + 1);
                input.truncate(at);
                input.extend_from_slice(&other[from..]);
            }
        }
    }
}

/// Byte ranges of the identifiers in `input`.
fn words(input: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &b) in input.iter().chain(std::iter::once(&b' ')).enumerate() {
        let w = b.is_ascii_alphabetic() || b == b'_';
        match (w, start) {
            (true, None) => start = Some(i),
            (false, Some(s0)) => {
                out.push((s0, i));
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// A failure the fuzzer found.
#[derive(Debug, Clone)]
pub struct Finding {
    /// "panic" or "hang".
    pub kind: &'static str,
    /// The execution it happened in.
    pub exec: u64,
    /// The panic message, or how long the input had run.
    pub message: String,
    /// The input.
    pub input: Vec<u8>,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct Report {
    /// The target.
    pub target: Target,
    /// Executions completed.
    pub execs: u64,
    /// Inputs accepted.
    pub accepted: u64,
    /// Refusals whose diagnostics lack a line (a whole-file error, or one that lost its place).
    pub unlocated: u64,
    /// One such input, to look at.
    pub unlocated_example: Option<(String, Vec<u8>)>,
    /// Corpus size at the end.
    pub corpus: usize,
    /// Distinct outcomes seen.
    pub outcomes: usize,
    /// Wall time.
    pub elapsed: Duration,
    /// The slowest execution and its input.
    pub slowest: (Duration, Vec<u8>),
    /// Panics and hangs.
    pub findings: Vec<Finding>,
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let secs = self.elapsed.as_secs_f64();
        write!(
            f,
            "{:<9} {:>9} execs in {:>7.1} s ({:>7.0}/s), {} accepted, {} outcomes, corpus {}, \
             {} unlocated, slowest {:.1} ms ({} B), {} panics, {} hangs",
            self.target.name(),
            self.execs,
            secs,
            self.execs as f64 / secs.max(1e-9),
            self.accepted,
            self.outcomes,
            self.corpus,
            self.unlocated,
            self.slowest.0.as_secs_f64() * 1e3,
            self.slowest.1.len(),
            self.findings.iter().filter(|x| x.kind == "panic").count(),
            self.findings.iter().filter(|x| x.kind == "hang").count(),
        )
    }
}

thread_local! {
    static LAST_PANIC: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

/// Panics are caught and reported by the run; the default hook would print each one.
fn quiet_panics() {
    static ONCE: OnceLock<()> = OnceLock::new();
    ONCE.get_or_init(|| {
        panic::set_hook(Box::new(|info| {
            let msg = format!("{info}");
            LAST_PANIC.with(|p| *p.borrow_mut() = msg);
        }));
    });
}

/// Runs `execs` executions on `t` from `seed`, stopping early after `stop_after` findings; each
/// execution is watched for hangs. With `dump_from` = (N, path), each input from execution N on
/// is written to `path` before it runs: after an abort (which kills the process) the file holds
/// the input that caused it.
pub fn run(
    t: Target,
    seed: u64,
    execs: u64,
    stop_after: usize,
    dump_from: Option<(u64, PathBuf)>,
    mut progress: impl FnMut(&Report) + Send + 'static,
) -> Report {
    quiet_panics();
    // The watchdog's view of the running execution: its start (ms since `t0`, 0 = idle), number
    // and input.
    let t0 = Instant::now();
    let started = Arc::new(AtomicU64::new(0));
    let current = Arc::new(Mutex::new((0u64, Vec::new())));
    let done = Arc::new(AtomicBool::new(false));
    let (tx, rx) = std::sync::mpsc::channel::<Report>();
    {
        let (started, current, done) = (started.clone(), current.clone(), done.clone());
        std::thread::Builder::new()
            .name(format!("fuzz-{}", t.name()))
            // The default stack, as the live server's loader thread has: a deep input that
            // overflows it would abort `watch`.
            .spawn(move || {
                let mut fz = Fuzzer::new(t, seed);
                let mut rep = Report {
                    target: t,
                    execs: 0,
                    accepted: 0,
                    unlocated: 0,
                    unlocated_example: None,
                    corpus: 0,
                    outcomes: 0,
                    elapsed: Duration::ZERO,
                    slowest: (Duration::ZERO, Vec::new()),
                    findings: Vec::new(),
                };
                let mut last_progress = Instant::now();
                for i in 0..execs {
                    if done.load(Ordering::Relaxed) {
                        break;
                    }
                    let input = fz.next_input();
                    if let Some((at, path)) = &dump_from {
                        if i >= *at {
                            std::fs::write(path, &input).unwrap();
                        }
                    }
                    current.lock().unwrap().clone_from(&(i, input.clone()));
                    let s = Instant::now();
                    started.store(1 + (s - t0).as_millis() as u64, Ordering::SeqCst);
                    let res = panic::catch_unwind(AssertUnwindSafe(|| execute(t, &input)));
                    started.store(0, Ordering::SeqCst);
                    let took = s.elapsed();
                    rep.execs += 1;
                    if took > rep.slowest.0 {
                        rep.slowest = (took, input.clone());
                    }
                    match res {
                        Ok(o) => {
                            match &o {
                                Outcome::Ok => rep.accepted += 1,
                                Outcome::Refused { located: false, .. } => {
                                    rep.unlocated += 1;
                                    if rep.unlocated_example.is_none() {
                                        if let Outcome::Refused { shape, .. } = &o {
                                            rep.unlocated_example =
                                                Some((shape.clone(), input.clone()));
                                        }
                                    }
                                }
                                Outcome::Refused { .. } => {}
                            }
                            fz.observe(input, o);
                        }
                        Err(_) => {
                            let message = LAST_PANIC.with(|p| p.borrow().clone());
                            rep.findings.push(Finding {
                                kind: "panic",
                                exec: i,
                                message,
                                input,
                            });
                            if rep.findings.len() >= stop_after {
                                break;
                            }
                        }
                    }
                    if last_progress.elapsed() > Duration::from_secs(10) {
                        last_progress = Instant::now();
                        rep.elapsed = t0.elapsed();
                        rep.corpus = fz.corpus_len();
                        rep.outcomes = fz.seen.len();
                        progress(&rep);
                    }
                }
                rep.elapsed = t0.elapsed();
                rep.corpus = fz.corpus_len();
                rep.outcomes = fz.seen.len();
                tx.send(rep).ok();
            })
            .unwrap();
    }
    loop {
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(rep) => return rep,
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                panic!("the fuzzing thread died without a report");
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
        }
        let s = started.load(Ordering::SeqCst);
        let now = 1 + t0.elapsed().as_millis() as u64;
        if s != 0 && now.saturating_sub(s) > HANG.as_millis() as u64 {
            // The worker cannot be stopped; report the hang and leave it running.
            done.store(true, Ordering::SeqCst);
            let (exec, input) = current.lock().unwrap().clone();
            return Report {
                target: t,
                execs: exec,
                accepted: 0,
                unlocated: 0,
                unlocated_example: None,
                corpus: 0,
                outcomes: 0,
                elapsed: t0.elapsed(),
                slowest: (Duration::from_millis(now - s), input.clone()),
                findings: vec![Finding {
                    kind: "hang",
                    exec,
                    message: format!("still running after {} ms", now - s),
                    input,
                }],
            };
        }
    }
}

/// Writes each finding's input under `dir` as `TARGET-KIND-EXEC.bin`; returns the paths.
pub fn save_findings(rep: &Report, dir: &Path) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).unwrap();
    rep.findings
        .iter()
        .map(|f| {
            let p = dir.join(format!("{}-{}-{}.bin", rep.target.name(), f.kind, f.exec));
            std::fs::write(&p, &f.input).unwrap();
            p
        })
        .collect()
}
