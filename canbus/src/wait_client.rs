//! `--wait-client SECONDS`: how long a socketcand server waits for a client before a run
//! starts ([`crate::socketcand::SocketcandServer::wait_for_client`]). The bound is checked here
//! once, for `canbus-demo` (which fails without a client) and `walker sil` (which starts the
//! walk anyway).

use std::time::Duration;

/// Longest wait for a client that `--wait-client` accepts \[s\] (a day).
pub const MAX_WAIT_CLIENT_S: f64 = 86_400.0;

/// The wait for a client that `--wait-client SECONDS` asks for: finite, from 0 to
/// [`MAX_WAIT_CLIENT_S`]; else a message naming the option and the value.
///
/// # Errors
/// The message, for a value outside the bound (negative, not finite, over a day).
pub fn wait_client_timeout(seconds: f64) -> Result<Duration, String> {
    Some(seconds)
        .filter(|w| (0.0..=MAX_WAIT_CLIENT_S).contains(w))
        .and_then(|w| Duration::try_from_secs_f64(w).ok())
        .ok_or_else(|| {
            format!("--wait-client {seconds:?}: expected seconds in [0, {MAX_WAIT_CLIENT_S}]")
        })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn wait_client_timeouts_are_bounded() {
        assert_eq!(wait_client_timeout(0.0), Ok(Duration::ZERO));
        assert_eq!(wait_client_timeout(2.5), Ok(Duration::from_millis(2500)));
        assert!(wait_client_timeout(MAX_WAIT_CLIENT_S).is_ok());
        for bad in [
            -1.0,
            -1e-9,
            f64::NAN,
            f64::INFINITY,
            MAX_WAIT_CLIENT_S + 1.0,
        ] {
            let e = wait_client_timeout(bad).unwrap_err();
            assert!(e.contains("--wait-client"), "{e}");
        }
    }
}
