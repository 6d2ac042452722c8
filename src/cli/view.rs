//! `shoal view DIR [--open]`: writes the self-contained replay page of a recorded run.

use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `shoal view`.
#[derive(clap::Args, Debug, Default)]
pub struct ViewArgs {
    /// A run folder written by `shoal run`, or a live session's record (`shoal watch --record`).
    pub dir: PathBuf,
    /// Open the page in the default browser afterwards.
    #[arg(long)]
    pub open: bool,
}

/// Runs `shoal view`.
pub fn view(args: ViewArgs) -> anyhow::Result<ExitCode> {
    let mut dir = args.dir.clone();
    // A live session's record holds versions, not frames: re-run it once into `replay/`.
    if shoal::live::record::is_record(&dir) && !dir.join("manifest.json").exists() {
        let out = dir.join("replay");
        if !out.join("manifest.json").exists() {
            match super::run::replay_live(&dir, &out, None, true)? {
                Ok(o) if o.complete => {}
                Ok(_) => return Ok(ExitCode::from(130)),
                Err(d) => return Ok(super::report(&d)),
            }
        }
        println!(
            "{} is a live session record: its re-run is in {}",
            dir.display(),
            out.display()
        );
        dir = out;
    }
    let page = match shoal::view::write_html(&dir) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            return Ok(ExitCode::from(super::BAD_INPUT));
        }
    };
    println!("viewer written to {}", page.display());
    if args.open {
        let opener = if cfg!(target_os = "macos") {
            "open"
        } else {
            "xdg-open"
        };
        match std::process::Command::new(opener).arg(&page).spawn() {
            Ok(_) => println!("opened with {opener}"),
            Err(e) => eprintln!("could not open it with {opener}: {e}; open the file in a browser"),
        }
    }
    Ok(ExitCode::SUCCESS)
}
