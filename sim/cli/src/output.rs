//! Everything `walker` writes: standard output, standard error and the files its options
//! name. Every write reports its error instead of panicking (as `println!` does); `main` turns
//! a broken pipe on standard output into a quiet exit 0 (as `ls | head` does) and any other
//! write error into exit code 1 with a message naming what could not be written.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Standard output could not be written (a closed pipe, a full disk).
#[derive(Debug, thiserror::Error)]
#[error("writing to standard output: {0}")]
pub struct StdoutError(#[source] pub std::io::Error);

impl StdoutError {
    /// True when the reader went away (`walker scenes | head -1`): not worth a message.
    pub fn is_broken_pipe(&self) -> bool {
        self.0.kind() == std::io::ErrorKind::BrokenPipe
    }
}

/// A file or folder an option names could not be created or written; names the option and
/// the path.
#[derive(Debug, thiserror::Error)]
#[error("{flag} `{}`: {source}", path.display())]
pub struct PathError {
    /// The option (`--out`, `--plot`, `--candump`).
    pub flag: &'static str,
    /// The path it names.
    pub path: PathBuf,
    /// What went wrong.
    #[source]
    pub source: std::io::Error,
}

impl PathError {
    /// The error of `flag`'s `path`.
    pub fn new(flag: &'static str, path: &Path, source: std::io::Error) -> Self {
        PathError {
            flag,
            path: path.to_path_buf(),
            source,
        }
    }
}

/// Writes text output with `print` into a buffered, locked standard output and flushes it;
/// every error of `print` or of the flush comes back as a [`StdoutError`].
pub fn text(print: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<(), StdoutError> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    print(&mut out).map_err(StdoutError)?;
    out.flush().map_err(StdoutError)
}

/// A line on standard error (a note or an error message). If standard error itself cannot be
/// written there is nowhere left to say so: the line is dropped instead of panicking as
/// `eprintln!` does.
pub fn note(line: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "{}", sanitized(&line.to_string()));
}

/// `text` with every control character but newline and tab escaped (`\u{1b}`): a message that
/// quotes a user's file or flag (a TOML error echoes the offending line) never sends terminal
/// escape sequences to the terminal.
pub fn sanitized(text: &str) -> std::borrow::Cow<'_, str> {
    if !text
        .chars()
        .any(|c| c.is_control() && c != '\n' && c != '\t')
    {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() && c != '\n' && c != '\t' {
            out.push_str(&c.escape_unicode().to_string());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// Creates the folder `dir` that option `flag` names (and its parents).
pub fn create_dir(flag: &'static str, dir: &Path) -> Result<(), PathError> {
    std::fs::create_dir_all(dir).map_err(|e| PathError::new(flag, dir, e))
}

/// Writes `contents` to `path`, a file in the folder option `flag` names.
pub fn write_file(flag: &'static str, path: &Path, contents: &str) -> Result<(), PathError> {
    std::fs::write(path, contents).map_err(|e| PathError::new(flag, path, e))
}
