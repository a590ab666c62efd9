//! The engine stands alone: it depends on no firmware, CAN or command-line crate (those link
//! the engine, never the other way round; docs/engine.md).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

/// Every dependency the engine may have: the numerics, serialisation, errors, rayon for
/// parallel stride evaluations (independent Jacobian columns, parameter sides), the
/// dependency-free extension profile it shares with the firmware, `libm` (musl's math, also
/// the firmware's) for the planar fast path's `sincos`, `libc` for opening a user's file
/// without blocking (`O_NONBLOCK`), and `rand`, `rand_chacha`, `rand_distr` for the rough
/// floor's seeded normal draws, `statrs` for the chi-square quantiles of the first-passage
/// time's exact interval (the same version the `cmaes` optimiser uses), and `cmaes` for
/// `walker optimize` (a well-kept implementation of Hansen's CMA-ES with restarts, seeded, on
/// the same nalgebra; without its plotting), and `ciborium` for an optimisation's evaluations
/// sent to and from a cluster's workers bit for bit (CBOR; already in the lock through
/// criterion).
const ALLOWED: [&str; 16] = [
    "ankle-profile",
    "nalgebra",
    "num-dual",
    "serde",
    "serde_json",
    "toml",
    "thiserror",
    "rayon",
    "libm",
    "libc",
    "rand",
    "rand_chacha",
    "rand_distr",
    "statrs",
    "cmaes",
    "ciborium",
];

const FORBIDDEN: [&str; 12] = [
    "firmware",
    "protocol",
    "canbus",
    "sil",
    "walker-cli",
    "embedded-hal",
    "embedded-can",
    "nb",
    "heapless",
    "defmt",
    "clap",
    "anyhow",
];

#[test]
fn the_engine_depends_on_no_firmware_can_or_cli_crate() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    let manifest: toml::Table = std::fs::read_to_string(&path).unwrap().parse().unwrap();
    let deps = manifest["dependencies"].as_table().unwrap();
    assert!(
        deps.contains_key("nalgebra"),
        "read the engine's dependencies"
    );
    for name in FORBIDDEN {
        assert!(
            !deps.contains_key(name),
            "the engine depends on `{name}` ({})",
            path.display()
        );
    }
    for name in deps.keys() {
        assert!(
            ALLOWED.contains(&name.as_str()),
            "the engine depends on `{name}`, which is not on the allowed list ({})",
            path.display()
        );
    }
    for (section, value) in &manifest {
        if section == "target" {
            for (cfg, table) in value.as_table().unwrap() {
                let deps = table.get("dependencies").and_then(|d| d.as_table());
                for name in FORBIDDEN {
                    assert!(
                        !deps.is_some_and(|d| d.contains_key(name)),
                        "the engine depends on `{name}` for {cfg}"
                    );
                }
            }
        }
    }
}
