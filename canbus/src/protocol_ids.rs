//! The identifiers the walker's bus carries (the protocol's message table), and the check that
//! a fault filtering on an identifier can ever apply: a fault on an identifier no node sends
//! would do nothing, silently.

use crate::fault::{FaultKind, FaultSpec};

/// Every identifier of the protocol's message table, sorted, each with its message and node
/// (e.g. `(0x022, "HeelStrike LEFT_ANKLE")`).
pub fn protocol_ids() -> Vec<(u16, String)> {
    let mut ids: Vec<(u16, String)> = protocol::MESSAGES
        .iter()
        .flat_map(|m| {
            m.node_fields().map(move |node| {
                let id = protocol::CanId::new(m.class, node).raw();
                let who = match m.direction {
                    protocol::signal::Direction::FromNode(_) => m.sender_name(node),
                    protocol::signal::Direction::ToNode(targets) => targets
                        .iter()
                        .find(|t| t.raw() == node)
                        .map_or("?", |t| t.dbc_name()),
                };
                (id, format!("{} {who}", m.name))
            })
        })
        .collect();
    ids.sort();
    ids
}

/// A fault whose filter names an identifier no node of the walker's bus sends.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "no node sends identifier 0x{id:03X}, so the fault would never apply (identifiers on the \
     bus: {known})"
)]
pub struct UnknownFaultId {
    /// The offending identifier.
    pub id: u16,
    /// The identifiers of the protocol's message table, each with its message and node.
    pub known: String,
}

/// Checks that `fault`, if it filters on an identifier (`drop`, `delay`, `corrupt`), names one
/// the protocol uses. A babbler's own identifier may be anything.
///
/// # Errors
/// [`UnknownFaultId`] naming the identifiers that exist.
pub fn check_fault_id(fault: &FaultSpec) -> Result<(), UnknownFaultId> {
    let filter = match &fault.kind {
        FaultKind::Drop { filter, .. }
        | FaultKind::Delay { filter, .. }
        | FaultKind::Corrupt { filter, .. } => Some(filter),
        FaultKind::Babble { .. } | FaultKind::BusOff { .. } => None,
    };
    match filter.and_then(|f| f.id) {
        Some(id) if !protocol_ids().iter().any(|(known, _)| *known == id) => Err(UnknownFaultId {
            id,
            known: protocol_ids()
                .iter()
                .map(|(id, name)| format!("0x{id:03X} {name}"))
                .collect::<Vec<_>>()
                .join(", "),
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_on_identifiers_the_bus_carries_pass_and_others_name_them() {
        let ok: FaultSpec = "drop:id=0x022,count=5"
            .parse()
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(check_fault_id(&ok), Ok(()));
        let babble: FaultSpec = "babble:node=3,id=0x7FF"
            .parse()
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(check_fault_id(&babble), Ok(()));
        let bad: FaultSpec = "drop:id=0x101,count=5"
            .parse()
            .unwrap_or_else(|e| panic!("{e}"));
        let e = check_fault_id(&bad)
            .err()
            .unwrap_or_else(|| panic!("0x101 accepted"));
        assert_eq!(e.id, 0x101);
        assert!(e.known.contains("0x022 HeelStrike"), "{}", e.known);
    }

    #[test]
    fn the_identifier_table_is_the_protocol_table() {
        let ids = protocol_ids();
        let n: usize = protocol::MESSAGES
            .iter()
            .map(|m| m.node_fields().count())
            .sum();
        assert_eq!(ids.len(), n);
        assert!(ids.windows(2).all(|w| w[0].0 < w[1].0), "{ids:?}");
        for (id, _) in &ids {
            assert!(protocol::CanId::from_raw(*id).is_ok(), "0x{id:03X}");
        }
    }
}
