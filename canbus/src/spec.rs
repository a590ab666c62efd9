//! The `kind[:key=value[,key=value]...]` text form of injected faults, parsed once for every
//! kind of fault (the bus's [`crate::FaultSpec`], the simulator's encoder faults).
//!
//! [`Spec::parse`] splits off the kind, checks it against the caller's list of kinds and
//! their keys, and splits the rest into `key=value` pairs (whitespace around each trimmed),
//! refusing a part without `=`, a key the kind does not take and a key given twice. The typed
//! lookups ([`Spec::optional`], [`Spec::required`]) turn a value into the caller's type or a
//! [`SpecError`] naming the key, the value and what was expected. Each caller maps
//! [`SpecError`] into its own error type, which words the message for its kind of fault.

use thiserror::Error;

/// Why a `kind:key=value,...` text was refused. Every variant names the kind and the
/// offending part.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum SpecError {
    /// The text before `:` is not one of the caller's kinds.
    #[error("unknown kind `{kind}`")]
    UnknownKind {
        /// The offending kind.
        kind: String,
    },
    /// A part without `=` (or an empty part).
    #[error("`{part}` in `{kind}` is not of the form key=value")]
    NotKeyValue {
        /// The kind.
        kind: String,
        /// The offending part.
        part: String,
    },
    /// A key this kind does not take.
    #[error("`{kind}` has no key `{key}` (allowed: {allowed})")]
    UnknownKey {
        /// The kind.
        kind: String,
        /// The offending key.
        key: String,
        /// The keys the kind takes, comma separated.
        allowed: &'static str,
    },
    /// A key given twice.
    #[error("key `{key}` given twice in `{kind}`")]
    DuplicateKey {
        /// The kind.
        kind: String,
        /// The repeated key.
        key: String,
    },
    /// A value that does not parse or is out of range.
    #[error("bad value `{value}` for `{key}` in `{kind}`: {reason}")]
    BadValue {
        /// The kind.
        kind: String,
        /// The key.
        key: String,
        /// The offending value.
        value: String,
        /// What was expected.
        reason: &'static str,
    },
    /// A key the kind requires is missing.
    #[error("`{kind}` needs `{key}=`")]
    MissingKey {
        /// The kind.
        kind: String,
        /// The missing key.
        key: &'static str,
    },
}

/// A `kind:key=value,...` text split into its kind and its pairs (borrowing the text).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Spec<'a> {
    kind: &'a str,
    pairs: Vec<(&'a str, &'a str)>,
}

impl<'a> Spec<'a> {
    /// Split `text` into its kind (before the first `:`) and its `key=value` pairs (after it,
    /// separated by `,`). `allowed_keys` gives the keys a kind takes, as `"a, b, c"`, or
    /// `None` when the kind is unknown.
    ///
    /// # Errors
    /// [`SpecError::UnknownKind`], then, part by part in order,
    /// [`SpecError::NotKeyValue`], [`SpecError::UnknownKey`] or [`SpecError::DuplicateKey`].
    pub fn parse(
        text: &'a str,
        allowed_keys: impl FnOnce(&str) -> Option<&'static str>,
    ) -> Result<Self, SpecError> {
        let (kind, rest) = match text.split_once(':') {
            Some((k, r)) => (k.trim(), Some(r)),
            None => (text.trim(), None),
        };
        let Some(allowed) = allowed_keys(kind) else {
            return Err(SpecError::UnknownKind { kind: kind.into() });
        };
        let mut pairs: Vec<(&str, &str)> = Vec::new();
        for part in rest.into_iter().flat_map(|r| r.split(',')) {
            let part = part.trim();
            let Some((k, v)) = part.split_once('=') else {
                return Err(SpecError::NotKeyValue {
                    kind: kind.into(),
                    part: part.into(),
                });
            };
            let (k, v) = (k.trim(), v.trim());
            if !allowed.split(", ").any(|a| a == k) {
                return Err(SpecError::UnknownKey {
                    kind: kind.into(),
                    key: k.into(),
                    allowed,
                });
            }
            if pairs.iter().any(|(pk, _)| *pk == k) {
                return Err(SpecError::DuplicateKey {
                    kind: kind.into(),
                    key: k.into(),
                });
            }
            pairs.push((k, v));
        }
        Ok(Spec { kind, pairs })
    }

    /// The kind (trimmed).
    pub fn kind(&self) -> &'a str {
        self.kind
    }

    /// The raw value of `key`, if given (trimmed).
    pub fn get(&self, key: &str) -> Option<&'a str> {
        self.pairs.iter().find(|(k, _)| *k == key).map(|(_, v)| *v)
    }

    /// The value of `key` through `parse`, `None` when the key is not given.
    ///
    /// # Errors
    /// [`SpecError::BadValue`] with `reason` when `parse` refuses the value.
    pub fn optional<T>(
        &self,
        key: &str,
        reason: &'static str,
        parse: impl FnOnce(&str) -> Option<T>,
    ) -> Result<Option<T>, SpecError> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => parse(v).map(Some).ok_or_else(|| self.bad(key, v, reason)),
        }
    }

    /// The value of `key` through `parse`; the key must be given.
    ///
    /// # Errors
    /// [`SpecError::MissingKey`] when it is not, [`SpecError::BadValue`] with `reason` when
    /// `parse` refuses the value.
    pub fn required<T>(
        &self,
        key: &'static str,
        reason: &'static str,
        parse: impl FnOnce(&str) -> Option<T>,
    ) -> Result<T, SpecError> {
        self.optional(key, reason, parse)?
            .ok_or_else(|| self.missing(key))
    }

    /// A [`SpecError::BadValue`] for `key`'s value `value` (for checks across keys).
    pub fn bad(&self, key: &str, value: &str, reason: &'static str) -> SpecError {
        SpecError::BadValue {
            kind: self.kind.into(),
            key: key.into(),
            value: value.into(),
            reason,
        }
    }

    /// A [`SpecError::MissingKey`] for `key`.
    pub fn missing(&self, key: &'static str) -> SpecError {
        SpecError::MissingKey {
            kind: self.kind.into(),
            key,
        }
    }
}

/// A time in milliseconds (finite, not negative) \[ms\], for [`Spec::optional`] and
/// [`Spec::required`].
pub fn parse_ms(value: &str) -> Option<f64> {
    value
        .parse::<f64>()
        .ok()
        .filter(|ms| ms.is_finite() && *ms >= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(kind: &str) -> Option<&'static str> {
        (kind == "k").then_some("a, b")
    }

    #[test]
    fn splits_kind_and_pairs_and_names_the_bad_part() {
        let s = Spec::parse(" k : a = 1 , b=x", keys).unwrap();
        assert_eq!(
            (s.kind(), s.get("a"), s.get("b")),
            ("k", Some("1"), Some("x"))
        );
        assert_eq!(
            s.optional("a", "an integer", |v| v.parse::<u8>().ok()),
            Ok(Some(1))
        );
        assert_eq!(
            s.required("b", "an integer", |v| v.parse::<u8>().ok()),
            Err(SpecError::BadValue {
                kind: "k".into(),
                key: "b".into(),
                value: "x".into(),
                reason: "an integer"
            })
        );
        let bare = Spec::parse("k", keys).unwrap();
        assert_eq!(bare.optional("a", "", |_| Some(())), Ok(None));
        assert_eq!(
            bare.required("a", "", |_| Some(())),
            Err(SpecError::MissingKey {
                kind: "k".into(),
                key: "a"
            })
        );
        let err = |t: &str| Spec::parse(t, keys).unwrap_err();
        assert_eq!(err("z:a=1"), SpecError::UnknownKind { kind: "z".into() });
        assert!(matches!(err("k:"), SpecError::NotKeyValue { part, .. } if part.is_empty()));
        assert!(matches!(err("k:a"), SpecError::NotKeyValue { part, .. } if part == "a"));
        assert!(
            matches!(err("k:c=1"), SpecError::UnknownKey { key, allowed: "a, b", .. } if key == "c")
        );
        assert!(matches!(err("k:a=1,a=2"), SpecError::DuplicateKey { key, .. } if key == "a"));
        assert_eq!(parse_ms("2.5"), Some(2.5));
        assert_eq!(parse_ms("-1"), None);
        assert_eq!(parse_ms("inf"), None);
    }
}
