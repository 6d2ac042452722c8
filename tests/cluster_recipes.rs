//! The recipes of `docs/cluster.md`, run as written on `sweeps/tiny_grid.ron` (2 axes × 3 seeds):
//! the Slurm batch script once per array task, the Kubernetes Indexed Job's command once per pod
//! index, and the `xargs` driver; each output folder, collected, holds the same `results.csv`
//! bytes as `shoal sweep run -j 2`. The docs' sweep and folders are swapped for the test's; every
//! other word of each command is the docs'.

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The fenced blocks of `docs/cluster.md` tagged `lang`.
fn blocks(lang: &str) -> Vec<String> {
    let doc = std::fs::read_to_string(repo().join("docs/cluster.md")).expect("docs/cluster.md");
    let mut out = Vec::new();
    let mut current: Option<String> = None;
    for line in doc.lines() {
        match &mut current {
            None if line.trim() == format!("```{lang}") => current = Some(String::new()),
            Some(text) if line.trim() == "```" => {
                out.push(std::mem::take(text));
                current = None;
            }
            Some(text) => {
                text.push_str(line);
                text.push('\n');
            }
            None => {}
        }
    }
    out
}

/// A shell command in the repository with the built `shoal` first on `PATH`.
fn sh(program: &str) -> Command {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_shoal"));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut c = Command::new(program);
    c.current_dir(repo()).env("PATH", path);
    c
}

fn check(c: &mut Command, what: &str) {
    let o = c.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        o.status.success(),
        "{what} failed:\n{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The docs' sweep and output folders replaced by the test's.
fn local(text: &str, out: &Path) -> String {
    let out = out.display().to_string();
    text.replace("sweeps/vision.ron", "sweeps/tiny_grid.ron")
        .replace("/shared/out/vision", &out)
        .replace("/out/vision", &out)
        .replace("out/vision", &out)
}

fn collected(out: &Path) -> Vec<u8> {
    check(
        sh("shoal").args(["sweep", "collect"]).arg(out),
        "shoal sweep collect",
    );
    std::fs::read(out.join("results.csv")).expect("results.csv")
}

#[test]
fn every_cluster_recipe_collects_the_table_a_local_run_does() {
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    check(
        sh("shoal")
            .args([
                "sweep",
                "run",
                "sweeps/tiny_grid.ron",
                "-j",
                "2",
                "-q",
                "--out",
            ])
            .arg(&reference),
        "shoal sweep run -j 2",
    );
    let expected = collected(&reference);
    assert!(
        String::from_utf8_lossy(&expected).lines().count() == 13,
        "12 runs and a header"
    );

    // Slurm: the batch script, once per array task (4 tasks), with the arguments its header
    // comment submits it with.
    let slurm = tmp.path().join("slurm");
    let script = blocks("bash")
        .into_iter()
        .find(|b| b.contains("#SBATCH"))
        .expect("a Slurm batch script in docs/cluster.md");
    let file = tmp.path().join("sweep.sbatch");
    std::fs::write(&file, &script).unwrap();
    for task in [2, 0, 3, 1] {
        check(
            sh("bash")
                .arg(&file)
                .arg("sweeps/tiny_grid.ron")
                .arg(&slurm)
                .env("SLURM_ARRAY_TASK_ID", task.to_string())
                .env("SLURM_ARRAY_TASK_COUNT", "4"),
            "the Slurm script",
        );
    }
    assert_eq!(collected(&slurm), expected, "Slurm array");

    // Kubernetes: the container's command, once per completion index.
    let k8s = tmp.path().join("k8s");
    let yaml = blocks("yaml").concat();
    let command = yaml
        .lines()
        .find_map(|l| l.trim().strip_prefix("- shoal sweep run"))
        .map(|rest| format!("shoal sweep run{rest}"))
        .expect("the Indexed Job's command in docs/cluster.md");
    let completions: usize = yaml
        .lines()
        .find_map(|l| l.trim().strip_prefix("completions:"))
        .and_then(|v| v.split('#').next()?.trim().parse().ok())
        .expect("completions: N");
    for index in (0..completions).rev() {
        check(
            sh("sh")
                .args(["-c", &local(&command, &k8s)])
                .env("JOB_COMPLETION_INDEX", index.to_string()),
            "the Indexed Job's command",
        );
    }
    assert_eq!(collected(&k8s), expected, "Indexed Job");

    // The xargs driver, whole.
    let driver = tmp.path().join("xargs");
    let loop_ = blocks("bash")
        .into_iter()
        .find(|b| b.contains("xargs"))
        .expect("the xargs driver in docs/cluster.md");
    check(
        sh("bash").args(["-euo", "pipefail", "-c", &local(&loop_, &driver)]),
        "the xargs driver",
    );
    assert_eq!(
        std::fs::read(driver.join("results.csv")).unwrap(),
        expected,
        "xargs driver"
    );
}
