//! Reading a small text file a user names (a scene file, a start state), bounded: only a
//! regular file (a FIFO would block the read forever, a device such as `/dev/zero` never ends),
//! at most a stated number of bytes (a huge file is refused, not read into memory), UTF-8.

use std::io::Read;
use std::path::Path;

/// Why a text file was not read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TextFileError {
    /// The path is a directory, FIFO, socket or device.
    #[error("not a regular file (a directory, FIFO, socket or device)")]
    NotARegularFile,
    /// Larger than the limit.
    #[error("larger than {max_bytes} bytes; {what} is a few kilobytes")]
    TooLarge {
        /// The limit \[bytes\].
        max_bytes: u64,
        /// What the file should be, for the message ("a scene file").
        what: &'static str,
    },
    /// The file system's error (missing file, permissions).
    #[error("{0}")]
    Io(String),
    /// Not UTF-8 text.
    #[error("not UTF-8 text")]
    NotUtf8,
}

/// `path` opened for reading with `O_NONBLOCK`, which never waits for a FIFO's writer (and
/// changes nothing for a regular file).
#[cfg(unix)]
fn open_without_blocking(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

/// `path` opened for reading.
#[cfg(not(unix))]
fn open_without_blocking(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

/// The text of the regular file at `path`, of at most `max_bytes` bytes; `what` names what it
/// should be in the error ("a scene file").
///
/// # Errors
/// A [`TextFileError`]: not a regular file (checked before it is opened, and on what was
/// opened), too large, unreadable
/// or not UTF-8.
pub fn read_text_file(
    path: &Path,
    max_bytes: u64,
    what: &'static str,
) -> Result<String, TextFileError> {
    let io = |e: std::io::Error| TextFileError::Io(e.to_string());
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(TextFileError::NotARegularFile);
    }
    let too_large = TextFileError::TooLarge { max_bytes, what };
    if meta.len() > max_bytes {
        return Err(too_large);
    }
    // Opened without blocking (a path swapped for a FIFO after the check above would block an
    // ordinary open until a writer came), and checked again on what was opened.
    let file = open_without_blocking(path).map_err(io)?;
    if !file.metadata().map_err(io)?.is_file() {
        return Err(TextFileError::NotARegularFile);
    }
    let mut bytes = Vec::new();
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large);
    }
    String::from_utf8(bytes).map_err(|_| TextFileError::NotUtf8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `read_text_file` opens, it opens without waiting: a FIFO with no writer (a path
    /// swapped for one after the type check) is opened at once and refused on what was opened.
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_opened_without_waiting_and_refused() {
        let fifo = std::env::temp_dir().join(format!("walker-text-fifo-{}", std::process::id()));
        let _ = std::fs::remove_file(&fifo);
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let (tx, rx) = std::sync::mpsc::channel();
        let path = fifo.clone();
        std::thread::spawn(move || {
            let f = open_without_blocking(&path).unwrap();
            let _ = tx.send(f.metadata().unwrap().is_file());
        });
        // a deadline that only turns a hang (an ordinary open) into a failure
        let is_file = rx
            .recv_timeout(std::time::Duration::from_secs(60))
            .expect("opened without waiting for a writer");
        assert!(!is_file);
        std::fs::remove_file(&fifo).unwrap();
    }

    #[test]
    fn only_small_regular_utf8_files_are_read() {
        let dir = std::env::temp_dir().join(format!("walker-text-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ok = dir.join("ok.toml");
        std::fs::write(&ok, "a = 1\n").unwrap();
        assert_eq!(read_text_file(&ok, 100, "a scene file").unwrap(), "a = 1\n");
        assert_eq!(
            read_text_file(&ok, 3, "a scene file"),
            Err(TextFileError::TooLarge {
                max_bytes: 3,
                what: "a scene file"
            })
        );
        assert_eq!(
            read_text_file(&dir, 100, "a scene file"),
            Err(TextFileError::NotARegularFile)
        );
        assert_eq!(
            read_text_file(Path::new("/dev/zero"), 100, "a scene file"),
            Err(TextFileError::NotARegularFile)
        );
        let bad = dir.join("bad.toml");
        std::fs::write(&bad, [0xff, 0xfe, 0x00]).unwrap();
        assert_eq!(
            read_text_file(&bad, 100, "a scene file"),
            Err(TextFileError::NotUtf8)
        );
        assert!(matches!(
            read_text_file(&dir.join("missing.toml"), 100, "a scene file"),
            Err(TextFileError::Io(_))
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
