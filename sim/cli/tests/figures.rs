//! The figures the commands write (issue #16): each as SVG, PNG and PDF side by side, labelled
//! in words (no code names, no literal asterisk markers), and `walker sweep --plot`'s
//! bifurcation diagram with its period doubling marked.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;
use common::{stderr, walker};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("walker-figures-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `dir/NAME.svg`, `.png` and `.pdf` exist and are what they claim; the SVG's text.
fn three_formats(dir: &Path, name: &str) -> String {
    let svg = std::fs::read_to_string(dir.join(format!("{name}.svg"))).expect("svg");
    assert!(
        svg.starts_with("<svg") && svg.ends_with("</svg>\n"),
        "{name}.svg"
    );
    let png = std::fs::read(dir.join(format!("{name}.png"))).expect("png");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{name}.png");
    assert!(
        png.len() > 10_000,
        "{name}.png has content: {} bytes",
        png.len()
    );
    let pdf = std::fs::read(dir.join(format!("{name}.pdf"))).expect("pdf");
    assert!(pdf.starts_with(b"%PDF-"), "{name}.pdf");
    assert!(
        String::from_utf8_lossy(&pdf[pdf.len() - 64..]).contains("%%EOF"),
        "{name}.pdf complete"
    );
    svg
}

/// The texts of the SVG's `<text>` elements.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let t = t.split_once('>')?.1;
            Some(t.split("</text>").next()?.to_string())
        })
        .collect()
}

#[test]
fn gait_figures_are_written_three_ways_in_words() {
    let dir = scratch("gait");
    let out = walker(&[
        "gait",
        "--scene",
        "compass",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    for name in ["eigenvalues", "joint_angles"] {
        let svg = three_formats(&dir, name);
        for t in texts(&svg) {
            assert!(!t.contains('_'), "a code name in {name}: {t}");
            assert_ne!(t.trim(), "*", "a literal asterisk in {name}");
            assert!(
                !t.contains("compass:"),
                "a scene id in the title of {name}: {t}"
            );
        }
    }
    let angles = std::fs::read_to_string(dir.join("joint_angles.svg")).unwrap();
    assert!(angles.contains("joint angle (rad)") && angles.contains(">swing leg<"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_plot_draws_the_bifurcation_diagram_and_max_multiplier() {
    let dir = scratch("sweep");
    let out = walker(&[
        "sweep",
        "--scene",
        "simplest",
        "--param",
        "slope",
        "--from",
        "0.013",
        "--to",
        "0.017",
        "--points",
        "9",
        "--max-period",
        "2",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let diagram = three_formats(&dir, "bifurcation_diagram");
    let modulus = three_formats(&dir, "max_multiplier");
    for svg in [&diagram, &modulus] {
        let t = texts(svg);
        for label in [
            "period-1 gait, stable",
            "period-1 gait, unstable",
            "period-2 gait, stable",
            "period doubling",
            "floor slope (rad)",
        ] {
            assert!(t.iter().any(|x| x == label), "no `{label}` in {t:?}");
        }
        // Stable solid, unstable dashed.
        assert!(svg.contains("<polyline") && svg.contains("stroke-dasharray"));
    }
    assert!(texts(&modulus)
        .iter()
        .any(|x| x == "largest |λ| of the stride map"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_refuses_an_unknown_coordinate_before_any_work() {
    let dir = scratch("sweep-bad");
    let out = walker(&[
        "sweep",
        "--scene",
        "simplest",
        "--param",
        "slope",
        "--from",
        "0.013",
        "--to",
        "0.017",
        "--points",
        "3",
        "--coordinate",
        "knee",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--coordinate `knee`"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.exists(), "no folder made for a refused command");
}
