//! Injectable bus faults and their command-line syntax.
//!
//! ```text
//! kind[:key=value[,key=value]...]
//!
//! drop:id=0x022,count=5        drop the next 5 frames with identifier 0x022 at the sender
//! drop:node=left,prob=0.1      drop each frame of node `left` with probability 0.1
//! delay:id=0x072,ms=20         hold each 0x072 frame back 20 ms before it may arbitrate
//! corrupt:prob=0.01            flip a bit in 1 % of transmissions (error frame, retransmit)
//! babble:node=3,id=0x7FF       node 3 sends frames with id 0x7FF back to back
//! busoff:node=left             every transmission of `left` fails until it is bus-off
//! ```
//!
//! Keys common to every kind: `from_ms`, `until_ms` (active window in simulated time, from
//! inclusive, until exclusive). Filters (`drop`, `delay`, `corrupt`): `id`, `node`. Identifiers
//! are hexadecimal with `0x` or decimal; nodes are a name (case-insensitive) or a number.

use std::fmt;

use thiserror::Error;

use crate::frame::Frame;
use crate::spec::{self, Spec, SpecError};

/// A node named in a fault: by name or by its number (the protocol's 4-bit node field).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NodeRef {
    /// Node name, compared case-insensitively.
    Name(String),
    /// Node number.
    Number(u8),
}

impl fmt::Display for NodeRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NodeRef::Name(n) => f.write_str(n),
            NodeRef::Number(n) => write!(f, "{n}"),
        }
    }
}

/// Which frames a fault applies to (all given conditions must hold).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FrameFilter {
    /// Only this identifier.
    pub id: Option<u16>,
    /// Only frames sent by this node.
    pub node: Option<NodeRef>,
}

/// How many of the matching frames a fault hits.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Hit {
    /// Probability of hitting each matching frame (seeded RNG of the bus); `None` = 1.
    pub prob: Option<f64>,
    /// Hit at most this many frames; `None` = unlimited.
    pub count: Option<u32>,
}

/// What a fault does.
#[derive(Clone, Debug, PartialEq)]
pub enum FaultKind {
    /// Discard matching frames at the sender before they reach the bus (no bus time used).
    Drop {
        /// Which frames.
        filter: FrameFilter,
        /// How many.
        hit: Hit,
    },
    /// Matching frames may arbitrate only `delay_ns` after they were queued.
    Delay {
        /// Which frames.
        filter: FrameFilter,
        /// Extra latency \[ns\].
        delay_ns: u64,
    },
    /// A bit error in matching transmissions: every receiver answers with an error frame, the
    /// transmitter's error counter rises by 8 and it retransmits the frame.
    Corrupt {
        /// Which frames.
        filter: FrameFilter,
        /// How many.
        hit: Hit,
    },
    /// The node always has a frame with `id` (8 bytes) pending: the bus is never idle.
    Babble {
        /// The babbling node.
        node: NodeRef,
        /// Identifier it babbles with.
        id: u16,
    },
    /// Every transmission of the node fails (as with a broken transceiver) until its transmit
    /// error counter passes 255 and it goes bus-off.
    BusOff {
        /// The node.
        node: NodeRef,
    },
}

/// A fault and the window of simulated time it is active in.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultSpec {
    /// What it does.
    pub kind: FaultKind,
    /// Active from this simulated time \[ns\] (inclusive).
    pub from_ns: u64,
    /// Active until this simulated time \[ns\] (exclusive); `None` = forever.
    pub until_ns: Option<u64>,
}

impl FaultSpec {
    /// True when the fault is active at simulated time `t_ns`.
    pub fn active_at(&self, t_ns: u64) -> bool {
        t_ns >= self.from_ns && self.until_ns.is_none_or(|u| t_ns < u)
    }
}

/// Why a fault string was refused. Every variant names the offending part.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum FaultParseError {
    /// The text before `:` is not a fault kind.
    #[error("unknown fault kind `{kind}` (expected drop, delay, corrupt, babble or busoff)")]
    UnknownKind {
        /// The offending kind.
        kind: String,
    },
    /// A `key=value` part without `=`, or an empty part.
    #[error("`{part}` in fault `{kind}` is not of the form key=value")]
    NotKeyValue {
        /// The fault kind.
        kind: String,
        /// The offending part.
        part: String,
    },
    /// A key this fault kind does not take.
    #[error("fault `{kind}` has no key `{key}` (allowed: {allowed})")]
    UnknownKey {
        /// The fault kind.
        kind: String,
        /// The offending key.
        key: String,
        /// The keys the kind takes.
        allowed: &'static str,
    },
    /// A key given twice.
    #[error("key `{key}` given twice in fault `{kind}`")]
    DuplicateKey {
        /// The fault kind.
        kind: String,
        /// The repeated key.
        key: String,
    },
    /// A value that does not parse or is out of range.
    #[error("bad value `{value}` for `{key}` in fault `{kind}`: {reason}")]
    BadValue {
        /// The fault kind.
        kind: String,
        /// The key.
        key: String,
        /// The offending value.
        value: String,
        /// What was expected.
        reason: &'static str,
    },
    /// A key the kind requires is missing.
    #[error("fault `{kind}` needs `{key}=`")]
    MissingKey {
        /// The fault kind.
        kind: String,
        /// The missing key.
        key: &'static str,
    },
}

fn allowed_keys(kind: &str) -> Option<&'static str> {
    Some(match kind {
        "drop" | "corrupt" => "id, node, prob, count, from_ms, until_ms",
        "delay" => "id, node, ms, from_ms, until_ms",
        "babble" => "node, id, from_ms, until_ms",
        "busoff" => "node, from_ms, until_ms",
        _ => return None,
    })
}

/// Parse an identifier: `0x` hexadecimal or decimal, at most 0x7FF.
fn parse_id(s: &str) -> Option<u16> {
    let v = match s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16).ok()?,
        None => s.parse::<u32>().ok()?,
    };
    u16::try_from(v).ok().filter(|v| *v <= 0x7FF)
}

fn parse_node(s: &str) -> Option<NodeRef> {
    if s.is_empty() {
        return None;
    }
    if let Ok(n) = s.parse::<u8>() {
        return Some(NodeRef::Number(n));
    }
    s.chars()
        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        .then(|| NodeRef::Name(s.to_string()))
}

/// A time in milliseconds (finite, 0 to 10¹² ms) as nanoseconds.
fn parse_ms_to_ns(s: &str) -> Option<u64> {
    spec::parse_ms(s)
        .filter(|ms| *ms <= 1e12)
        .map(|ms| (ms * 1e6).round() as u64)
}

impl From<SpecError> for FaultParseError {
    /// The same refusal, worded for a bus fault.
    fn from(e: SpecError) -> Self {
        match e {
            SpecError::UnknownKind { kind } => FaultParseError::UnknownKind { kind },
            SpecError::NotKeyValue { kind, part } => FaultParseError::NotKeyValue { kind, part },
            SpecError::UnknownKey { kind, key, allowed } => {
                FaultParseError::UnknownKey { kind, key, allowed }
            }
            SpecError::DuplicateKey { kind, key } => FaultParseError::DuplicateKey { kind, key },
            SpecError::BadValue {
                kind,
                key,
                value,
                reason,
            } => FaultParseError::BadValue {
                kind,
                key,
                value,
                reason,
            },
            SpecError::MissingKey { kind, key } => FaultParseError::MissingKey { kind, key },
        }
    }
}

impl std::str::FromStr for FaultSpec {
    type Err = FaultParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let spec = Spec::parse(s, allowed_keys)?;
        let ms = "a non-negative number of milliseconds";
        let id = spec.optional(
            "id",
            "an 11-bit identifier, 0x000..0x7FF or 0..2047",
            parse_id,
        )?;
        let node = spec.optional(
            "node",
            "a node name (letters, digits, _ or -) or number 0..255",
            parse_node,
        )?;
        let prob = spec.optional("prob", "a probability between 0 and 1", |v| {
            v.parse::<f64>().ok().filter(|p| (0.0..=1.0).contains(p))
        })?;
        // count=0 would hit nothing (the fault silently did nothing); past u32 is no count a
        // run can reach.
        let count = spec.optional(
            "count",
            "a whole number of frames from 1 to 4294967295",
            |v| v.parse::<u32>().ok().filter(|&c| c > 0),
        )?;
        let from_ns = spec.optional("from_ms", ms, parse_ms_to_ns)?.unwrap_or(0);
        let until_ns = spec.optional("until_ms", ms, parse_ms_to_ns)?;
        if until_ns.is_some_and(|u| u <= from_ns) {
            let v = spec.get("until_ms").unwrap_or_default();
            return Err(spec.bad("until_ms", v, "a time after from_ms").into());
        }
        let filter = FrameFilter {
            id,
            node: node.clone(),
        };
        let hit = Hit { prob, count };
        let kind = match spec.kind() {
            "drop" => FaultKind::Drop { filter, hit },
            "corrupt" => FaultKind::Corrupt { filter, hit },
            "delay" => FaultKind::Delay {
                filter,
                delay_ns: spec.required("ms", ms, parse_ms_to_ns)?,
            },
            "babble" => FaultKind::Babble {
                node: node.ok_or_else(|| spec.missing("node"))?,
                id: id.unwrap_or(Frame::MAX_ID),
            },
            _ => FaultKind::BusOff {
                node: node.ok_or_else(|| spec.missing("node"))?,
            },
        };
        Ok(FaultSpec {
            kind,
            from_ns,
            until_ns,
        })
    }
}

fn write_ms(f: &mut fmt::Formatter<'_>, key: &str, ns: u64) -> fmt::Result {
    write!(f, "{key}={}", ns as f64 / 1e6)
}

impl fmt::Display for FaultSpec {
    /// The canonical string form, which parses back to the same fault.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts: Vec<String> = Vec::new();
        let filter_parts = |filter: &FrameFilter, parts: &mut Vec<String>| {
            if let Some(id) = filter.id {
                parts.push(format!("id=0x{id:03X}"));
            }
            if let Some(n) = &filter.node {
                parts.push(format!("node={n}"));
            }
        };
        let hit_parts = |hit: &Hit, parts: &mut Vec<String>| {
            if let Some(p) = hit.prob {
                parts.push(format!("prob={p}"));
            }
            if let Some(c) = hit.count {
                parts.push(format!("count={c}"));
            }
        };
        let name = match &self.kind {
            FaultKind::Drop { filter, hit } => {
                filter_parts(filter, &mut parts);
                hit_parts(hit, &mut parts);
                "drop"
            }
            FaultKind::Corrupt { filter, hit } => {
                filter_parts(filter, &mut parts);
                hit_parts(hit, &mut parts);
                "corrupt"
            }
            FaultKind::Delay { filter, delay_ns } => {
                filter_parts(filter, &mut parts);
                parts.push(format!("ms={}", *delay_ns as f64 / 1e6));
                "delay"
            }
            FaultKind::Babble { node, id } => {
                parts.push(format!("node={node}"));
                parts.push(format!("id=0x{id:03X}"));
                "babble"
            }
            FaultKind::BusOff { node } => {
                parts.push(format!("node={node}"));
                "busoff"
            }
        };
        f.write_str(name)?;
        let mut sep = ':';
        for p in &parts {
            write!(f, "{sep}{p}")?;
            sep = ',';
        }
        if self.from_ns != 0 {
            write!(f, "{sep}")?;
            write_ms(f, "from_ms", self.from_ns)?;
            sep = ',';
        }
        if let Some(u) = self.until_ns {
            write!(f, "{sep}")?;
            write_ms(f, "until_ms", u)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn p(s: &str) -> Result<FaultSpec, FaultParseError> {
        s.parse()
    }

    #[test]
    fn parses_the_documented_examples() {
        assert_eq!(
            p("drop:id=0x101,count=5").unwrap().kind,
            FaultKind::Drop {
                filter: FrameFilter {
                    id: Some(0x101),
                    node: None
                },
                hit: Hit {
                    prob: None,
                    count: Some(5)
                }
            }
        );
        assert_eq!(
            p("delay:id=0x2A0,ms=20").unwrap().kind,
            FaultKind::Delay {
                filter: FrameFilter {
                    id: Some(0x2A0),
                    node: None
                },
                delay_ns: 20_000_000
            }
        );
        assert_eq!(
            p("corrupt:prob=0.01").unwrap().kind,
            FaultKind::Corrupt {
                filter: FrameFilter::default(),
                hit: Hit {
                    prob: Some(0.01),
                    count: None
                }
            }
        );
        assert_eq!(
            p("babble:node=3,id=0x7FF").unwrap().kind,
            FaultKind::Babble {
                node: NodeRef::Number(3),
                id: 0x7FF
            }
        );
        let b = p("busoff:node=left,from_ms=500").unwrap();
        assert_eq!(
            b.kind,
            FaultKind::BusOff {
                node: NodeRef::Name("left".into())
            }
        );
        assert_eq!(b.from_ns, 500_000_000);
        assert!(!b.active_at(499_999_999) && b.active_at(500_000_000));
    }

    #[test]
    fn errors_name_the_bad_part() {
        let e = p("smash:id=1").unwrap_err();
        assert!(e.to_string().contains("`smash`"), "{e}");
        let e = p("drop:id=0x800").unwrap_err();
        assert!(
            matches!(&e, FaultParseError::BadValue { key, value, .. } if key == "id" && value == "0x800"),
            "{e}"
        );
        assert!(e.to_string().contains("0x800"));
        let e = p("drop:prob=1.5").unwrap_err();
        assert!(e.to_string().contains("`1.5`") && e.to_string().contains("prob"));
        let e = p("delay:id=0x10").unwrap_err();
        assert_eq!(
            e,
            FaultParseError::MissingKey {
                kind: "delay".into(),
                key: "ms"
            }
        );
        let e = p("delay:ms=-3").unwrap_err();
        assert!(e.to_string().contains("`-3`"));
        for (bad, why) in [
            ("drop:id=0x072,count=0", "count=0 hits nothing"),
            ("drop:id=0x072,count=18446744073709551615", "past u32"),
            ("corrupt:id=0x072,count=-1", "negative"),
        ] {
            let e = p(bad).unwrap_err().to_string();
            assert!(
                e.contains("count") && e.contains("from 1 to 4294967295"),
                "{bad} ({why}): {e}"
            );
        }
        let e = p("busoff:node=left,count=3").unwrap_err();
        assert!(
            matches!(&e, FaultParseError::UnknownKey { key, .. } if key == "count"),
            "{e}"
        );
        let e = p("drop:id").unwrap_err();
        assert!(matches!(&e, FaultParseError::NotKeyValue { part, .. } if part == "id"));
        let e = p("drop:id=1,id=2").unwrap_err();
        assert!(matches!(&e, FaultParseError::DuplicateKey { key, .. } if key == "id"));
        let e = p("busoff").unwrap_err();
        assert!(matches!(e, FaultParseError::MissingKey { key: "node", .. }));
        let e = p("drop:from_ms=10,until_ms=5").unwrap_err();
        assert!(e.to_string().contains("until_ms"));
        let e = p("babble:node=le ft").unwrap_err();
        assert!(e.to_string().contains("le ft"));
    }

    fn arb_node() -> impl Strategy<Value = Option<NodeRef>> {
        prop_oneof![
            Just(None),
            any::<u8>().prop_map(|n| Some(NodeRef::Number(n))),
            "[a-z][a-z_]{0,8}".prop_map(|s| Some(NodeRef::Name(s))),
        ]
    }

    fn arb_filter() -> impl Strategy<Value = FrameFilter> {
        (proptest::option::of(0u16..0x800), arb_node())
            .prop_map(|(id, node)| FrameFilter { id, node })
    }

    fn arb_hit() -> impl Strategy<Value = Hit> {
        (
            proptest::option::of((0u32..=1000).prop_map(|p| f64::from(p) / 1000.0)),
            proptest::option::of(1..=u32::MAX),
        )
            .prop_map(|(prob, count)| Hit { prob, count })
    }

    fn arb_spec() -> impl Strategy<Value = FaultSpec> {
        let node = prop_oneof![
            any::<u8>().prop_map(NodeRef::Number),
            "[a-z][a-z_]{0,8}".prop_map(NodeRef::Name)
        ];
        let kind = prop_oneof![
            (arb_filter(), arb_hit()).prop_map(|(filter, hit)| FaultKind::Drop { filter, hit }),
            (arb_filter(), arb_hit()).prop_map(|(filter, hit)| FaultKind::Corrupt { filter, hit }),
            (arb_filter(), 0u64..10_000).prop_map(|(filter, ms)| FaultKind::Delay {
                filter,
                delay_ns: ms * 1_000_000
            }),
            (node.clone(), 0u16..0x800).prop_map(|(node, id)| FaultKind::Babble { node, id }),
            node.prop_map(|node| FaultKind::BusOff { node }),
        ];
        (kind, 0u64..5000, proptest::option::of(1u64..5000)).prop_map(|(kind, from, len)| {
            FaultSpec {
                kind,
                from_ns: from * 1_000_000,
                until_ns: len.map(|l| (from + l) * 1_000_000),
            }
        })
    }

    proptest! {
        #[test]
        fn display_parses_back(spec in arb_spec()) {
            let s = spec.to_string();
            prop_assert_eq!(p(&s), Ok(spec), "{}", s);
        }

        #[test]
        fn arbitrary_text_never_panics(s in ".{0,40}") {
            let _ = p(&s);
        }
    }
}
