//! What every loader shares: species, scenarios, scripts, terrain, formations and squads read
//! users' files through this module. Not a tick stage; the core below never reads a file.
//!
//! - [`diag`]: located diagnostics, and the one reader of users' files (regular files, UTF-8);
//! - [`parse`]: the RON options every file is read with, and RON's errors as diagnostics;
//! - [`locate`](mod@locate): the line and column where a name or a key's value is written;
//! - [`hints`]: "did you mean" suggestions for misspelt names;
//! - [`numbers`]: load-time number checks (finite, ranges, orders) and the size limits;
//! - [`overlay`]: texts read in place of files (an editor's unsaved buffers, a run's settings);
//! - [`ron_lex`], [`ron_patch`]: RON's tokens, and a text's value changed by key.

pub mod diag;
pub mod hints;
pub mod locate;
pub mod numbers;
pub mod overlay;
pub mod parse;
pub mod ron_lex;
pub mod ron_patch;

pub use diag::{read_bytes, read_text, Diagnostic, Diagnostics};
pub use hints::did_you_mean;
pub use locate::{locate, locate_key};
pub use numbers::NumberCheck;
pub use parse::{first_word, ron_diag, ron_options};
