//! The cost of transport under both of its key spellings.

use serde::ser::{Serialize, SerializeMap, Serializer};

/// Actuator work per unit mass and forward distance [J/(kg m)].
///
/// Flattened into a report, it writes two keys with the same number: the original
/// `cost_of_transport_J_per_kg_m` (upper-case `J`, kept for compatibility: other tools read
/// it) and its lower-snake-case twin `cost_of_transport_j_per_kg_m`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostOfTransport {
    /// The cost of transport [J/(kg m)].
    pub j_per_kg_m: f64,
}

impl CostOfTransport {
    /// The original key, kept for compatibility.
    pub const KEY_COMPAT: &'static str = "cost_of_transport_J_per_kg_m";
    /// The lower-snake-case key.
    pub const KEY: &'static str = "cost_of_transport_j_per_kg_m";
}

impl Serialize for CostOfTransport {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut m = serializer.serialize_map(Some(2))?;
        m.serialize_entry(Self::KEY_COMPAT, &self.j_per_kg_m)?;
        m.serialize_entry(Self::KEY, &self.j_per_kg_m)?;
        m.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Serialize)]
    struct Record {
        speed_m_s: f64,
        #[serde(flatten)]
        cost_of_transport: CostOfTransport,
    }

    #[test]
    fn flattened_it_writes_both_spellings_beside_the_other_keys_sorted() {
        let r = Record {
            speed_m_s: 0.5,
            cost_of_transport: CostOfTransport { j_per_kg_m: 0.25 },
        };
        let text = serde_json::to_string(&crate::report::to_json(&r).unwrap()).unwrap();
        assert_eq!(
            text,
            r#"{"cost_of_transport_J_per_kg_m":0.25,"cost_of_transport_j_per_kg_m":0.25,"speed_m_s":0.5}"#
        );
    }
}
