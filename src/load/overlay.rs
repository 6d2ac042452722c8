//! Texts read in place of files: an editor's unsaved buffers. Not a tick stage; only
//! [`super::read_text`] consults it, and only on the thread that called [`with`], so a run or a
//! `shoal check` (which never call it) reads the disk as before. While active it also records
//! every path read, which tells the language server what a file's check depends on.

use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

/// Unsaved texts by normalized path (see [`normalize`]).
pub type Texts = BTreeMap<PathBuf, Arc<str>>;

struct Active {
    texts: Texts,
    reads: BTreeSet<PathBuf>,
}

thread_local! {
    static ACTIVE: RefCell<Option<Active>> = const { RefCell::new(None) };
}

/// Removes `.` and `a/..` components without touching the file system, so that the same file
/// reached through `scenarios/../behaviors` and `behaviors` is one key and diagnostics name
/// files the way a user would. A path that comes to nothing is `.`.
pub fn normalize(p: &Path) -> PathBuf {
    let mut out: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    if out.is_empty() {
        PathBuf::from(".")
    } else {
        out.iter().collect()
    }
}

/// Runs `f` with `texts` read in place of those files, and returns its result with the
/// (normalized) paths every read in it asked for, overlaid or not. Calls do not nest: an inner
/// call's reads are not the outer one's.
pub fn with<R>(texts: &Texts, f: impl FnOnce() -> R) -> (R, BTreeSet<PathBuf>) {
    let before = ACTIVE.with(|a| {
        a.borrow_mut().replace(Active {
            texts: texts.clone(),
            reads: BTreeSet::new(),
        })
    });
    let r = f();
    let reads = ACTIVE.with(|a| {
        let mut a = a.borrow_mut();
        let mine = std::mem::replace(&mut *a, before);
        mine.map(|m| m.reads).unwrap_or_default()
    });
    (r, reads)
}

/// The overlaid text of `path` when an overlay is active and holds it; records the read.
pub(super) fn read(path: &Path) -> Option<String> {
    ACTIVE.with(|a| {
        let mut a = a.borrow_mut();
        let active = a.as_mut()?;
        let key = normalize(path);
        let text = active.texts.get(&key).map(|t| t.to_string());
        active.reads.insert(key);
        text
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalize_removes_dots_without_the_file_system() {
        let n = |p: &str| normalize(Path::new(p));
        assert_eq!(
            n("scenarios/../behaviors/a.ron"),
            Path::new("behaviors/a.ron")
        );
        assert_eq!(n("./a/./b"), Path::new("a/b"));
        assert_eq!(n("/p/x/../../q"), Path::new("/q"));
        // `..` that climbs above where the path starts is kept: nothing there is known.
        assert_eq!(n("../a/../b"), Path::new("../b"));
        assert_eq!(n("a/.."), Path::new("."));
        assert_eq!(n("."), Path::new("."));
    }

    #[test]
    fn overlaid_text_is_read_and_reads_are_recorded() {
        let mut texts = Texts::new();
        texts.insert(PathBuf::from("/p/behaviors/a.ron"), Arc::from("mine"));
        let (got, reads) = with(&texts, || {
            (
                read(Path::new("/p/scenarios/../behaviors/a.ron")),
                read(Path::new("/p/behaviors/b.ron")),
            )
        });
        assert_eq!(got, (Some("mine".to_string()), None));
        assert_eq!(reads.len(), 2);
        assert!(reads.contains(Path::new("/p/behaviors/b.ron")));
        // Outside `with`, nothing is overlaid.
        assert_eq!(read(Path::new("/p/behaviors/a.ron")), None);
    }
}
