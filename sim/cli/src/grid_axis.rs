//! A grid axis as an option gives it, `NAME=FROM:TO:N` (`walker stability-map --x`, `walker
//! basin --x`): a name and N values from FROM to TO, N bounded
//! ([`crate::limits::MAX_MAP_AXIS_POINTS`]).

use crate::input_error::InputError;
use crate::limits;
use sim::analysis::orbit_diagram::linspace;

/// The name (trimmed, not checked) and values of option `flag`'s `spec`; `example` shows the
/// form in the message of a spec that does not parse.
///
/// # Errors
/// No `=`, not three fields, a bound that is not a finite number, N not a count in 1 to
/// [`limits::MAX_MAP_AXIS_POINTS`], equal bounds for more than one value.
pub fn parse(flag: &str, spec: &str, example: &str) -> Result<(String, Vec<f64>), InputError> {
    let bad = |why: &str| InputError::Other(format!("{flag} `{spec}`: {why} (expected {example})"));
    let (name, range) = spec.split_once('=').ok_or_else(|| bad("no `=`"))?;
    let parts: Vec<&str> = range.split(':').map(str::trim).collect();
    let [from, to, n] = parts.as_slice() else {
        return Err(bad("expected three fields after `=`"));
    };
    let number = |what: &str, s: &str| -> Result<f64, InputError> {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(&format!("{what} `{s}` is not a finite number")))
    };
    let (from, to) = (number("FROM", from)?, number("TO", to)?);
    let n: usize = n
        .parse()
        .map_err(|_| bad(&format!("N `{n}` is not a count")))?;
    let n = limits::count(&format!("{flag} N"), n, 1, limits::MAX_MAP_AXIS_POINTS)?;
    if n > 1 && from == to {
        return Err(bad("FROM and TO are equal"));
    }
    Ok((name.trim().to_owned(), linspace(from, to, n)))
}
