//! The DBC file, rendered from [`crate::MESSAGES`]. Loadable by cantools in strict mode.

extern crate alloc;
extern crate std;

use alloc::string::String;
use core::fmt::Write as _;

use crate::id::{CanId, NodeId};
use crate::messages::MESSAGES;

/// Render the whole DBC file.
pub fn render() -> String {
    let mut out = String::new();
    // Writing to a String cannot fail; ignore the Ok.
    let _ = write_dbc(&mut out);
    out
}

fn receivers(sender: &str) -> String {
    let others: alloc::vec::Vec<&str> = NodeId::ALL
        .iter()
        .map(|n| n.dbc_name())
        .filter(|n| *n != sender)
        .collect();
    others.join(",")
}

fn write_dbc(out: &mut String) -> core::fmt::Result {
    writeln!(
        out,
        "VERSION \"walker-protocol-{}\"",
        crate::PROTOCOL_VERSION
    )?;
    writeln!(out)?;
    writeln!(out, "NS_ :")?;
    writeln!(out)?;
    writeln!(out, "BS_:")?;
    writeln!(out)?;
    let nodes: alloc::vec::Vec<&str> = NodeId::ALL.iter().map(|n| n.dbc_name()).collect();
    writeln!(out, "BU_: {}", nodes.join(" "))?;
    writeln!(out)?;

    let mut comments = String::new();
    let mut values = String::new();
    for m in MESSAGES {
        for node_raw in m.node_fields() {
            let id = CanId::new(m.class, node_raw).raw();
            let sender = m.sender_name(node_raw);
            writeln!(
                out,
                "BO_ {id} {}_{}: {} {sender}",
                m.name,
                m.node_suffix(node_raw),
                m.dlc
            )?;
            let rx = receivers(sender);
            for s in m.signals {
                let sign = if s.kind.signed() { '-' } else { '+' };
                writeln!(
                    out,
                    " SG_ {} : {}|{}@1{sign} ({},0) [{}|{}] \"{}\" {rx}",
                    s.name,
                    s.start_bit(),
                    s.bits(),
                    fmt_num(s.scale),
                    fmt_num(s.phys_min()),
                    fmt_num(s.phys_max()),
                    s.unit
                )?;
                writeln!(comments, "CM_ SG_ {id} {} \"{}\";", s.name, s.comment)?;
                if !s.choices.is_empty() {
                    write!(values, "VAL_ {id} {}", s.name)?;
                    for (raw, name) in s.choices.iter().rev() {
                        write!(values, " {raw} \"{name}\"")?;
                    }
                    writeln!(values, " ;")?;
                }
            }
            writeln!(out)?;
            writeln!(comments, "CM_ BO_ {id} \"{}\";", m.comment)?;
        }
    }
    out.push_str(&comments);
    out.push_str(&values);
    Ok(())
}

/// Shortest decimal that reads back to the same f64 (Rust's `Display` for f64 does this),
/// without exponent notation, which some DBC readers refuse.
fn fmt_num(v: f64) -> String {
    let s = alloc::format!("{v}");
    if s.contains('e') || s.contains('E') {
        alloc::format!("{v:.12}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dbc_lists_every_identifier_once() {
        let d = render();
        let bo: alloc::vec::Vec<&str> = d.lines().filter(|l| l.starts_with("BO_ ")).collect();
        let expected: usize = MESSAGES.iter().map(|m| m.node_fields().count()).sum();
        assert_eq!(bo.len(), expected);
        let mut ids: alloc::vec::Vec<&str> = bo
            .iter()
            .filter_map(|l| l.split_whitespace().nth(1))
            .collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), expected);
        assert!(d.contains("BO_ 114 AnkleState_LEFT_ANKLE: 7 LEFT_ANKLE"));
        assert!(d.contains(" SG_ angle : 0|16@1- (0.0001,0) [-3.2768|3.2767] \"rad\""));
    }

    #[test]
    fn numbers_have_no_exponent() {
        assert_eq!(fmt_num(1e-6), "0.000001");
        assert_eq!(fmt_num(0.0001), "0.0001");
        assert_eq!(fmt_num(-2147.483648), "-2147.483648");
    }
}
