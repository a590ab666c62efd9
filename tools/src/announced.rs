//! For the tests that start a server process and connect to it: the address it announces on
//! a line of its standard error.

use std::io::BufRead;
use std::time::{Duration, Instant};

/// Reads lines from `stderr` until one starts with `prefix` (after trimming) and returns the
/// rest of that line up to its first whitespace, e.g. `127.0.0.1:40123` from
/// `socketcand: listening on 127.0.0.1:40123`. Stops at the end of the stream or once
/// `budget` has passed since the call.
///
/// # Errors
/// The last line read (or why reading failed), when no line announced an address.
pub fn announced_address(
    stderr: &mut impl BufRead,
    prefix: &str,
    budget: Duration,
) -> Result<String, String> {
    let t0 = Instant::now();
    let mut line = String::new();
    while t0.elapsed() < budget {
        line.clear();
        match stderr.read_line(&mut line) {
            Ok(0) => break,
            Ok(_) => {}
            Err(e) => return Err(format!("reading stderr: {e}")),
        }
        if let Some(rest) = line.trim().strip_prefix(prefix) {
            if let Some(addr) = rest.split_whitespace().next() {
                return Ok(addr.to_string());
            }
        }
    }
    Err(format!("no line starting `{prefix}`; last: {line}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_address_after_the_prefix_is_read_and_anything_else_is_an_error() {
        let text =
            "note: starting\nsocketcand: serving the bus on 127.0.0.1:40123 (channel vcan0)\n";
        assert_eq!(
            announced_address(
                &mut text.as_bytes(),
                "socketcand: serving the bus on ",
                Duration::from_secs(1)
            ),
            Ok("127.0.0.1:40123".to_string())
        );
        assert!(announced_address(
            &mut "nothing here\n".as_bytes(),
            "socketcand: listening on ",
            Duration::from_secs(1)
        )
        .is_err());
    }
}
