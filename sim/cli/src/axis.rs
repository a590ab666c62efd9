//! One axis of a figure, written once for the line plots and the heat maps: its scale (linear
//! or base-10 logarithmic), the range it shows, the ticks (values, labels, major or minor) and
//! the SVG of the tick marks, grid lines and tick labels along an edge of the plot area.

use crate::svg_text::escape;
use std::fmt::Write as _;

/// How values map onto an axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    #[default]
    Linear,
    /// Base-10 logarithmic: decades equally spaced, ticks at the decades (labelled `10ᵏ`) and
    /// at 2…9 times them (unlabelled minor ticks). Values ≤ 0 cannot be shown and are left out.
    Log10,
}

impl Scale {
    /// The value as it is laid out along the axis (itself, or its base-10 logarithm); `None`
    /// for a value this scale cannot show (not finite, or ≤ 0 on a log axis).
    pub fn to_axis(self, v: f64) -> Option<f64> {
        match self {
            Scale::Linear => v.is_finite().then_some(v),
            Scale::Log10 => (v.is_finite() && v > 0.0).then(|| v.log10()),
        }
    }
}

/// A tick on an axis: its position (in axis units: the value, or its logarithm on a log axis),
/// its label (empty for a minor tick) and whether it is a major tick.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// Position in axis units.
    pub at: f64,
    /// Label (empty for minor ticks).
    pub label: String,
    /// A major (labelled, with a grid line) or minor tick.
    pub major: bool,
}

/// A "nice" tick spacing (1, 2 or 5 times a power of ten) giving about `target` intervals
/// over `span`.
pub fn nice_step(span: f64, target: usize) -> f64 {
    let raw = span / target.max(1) as f64;
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    let nice = if f < 1.5 {
        1.0
    } else if f < 3.0 {
        2.0
    } else if f < 7.0 {
        5.0
    } else {
        10.0
    };
    nice * mag
}

/// `v` with as many decimals as the tick spacing `step` needs, a minus sign (−) for negative
/// values, and never "-0".
pub fn fmt_tick(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).clamp(0.0, 12.0) as usize;
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s.chars().all(|c| matches!(c, '0' | '.' | '-')) {
        s.trim_start_matches('-').to_string()
    } else {
        // A true minus sign, as typeset.
        s.replacen('-', "−", 1)
    }
}

/// `10ᵏ` with the exponent in Unicode superscripts (rendered by any font that has them, in
/// SVG, PNG and PDF alike).
pub fn power_of_ten(k: i32) -> String {
    const SUPERSCRIPT: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if k < 0 {
        s.push('⁻');
    }
    for d in k.unsigned_abs().to_string().chars() {
        if let Some(i) = d.to_digit(10) {
            s.push(SUPERSCRIPT[i as usize]);
        }
    }
    s
}

/// The range an axis shows around data spanning `lo..hi` (axis units): 5 % padding on a
/// linear axis (a unit around a single value), whole decades on a log axis.
pub fn padded_range(scale: Scale, lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return match scale {
            Scale::Linear => (0.0, 1.0),
            Scale::Log10 => (0.0, 1.0),
        };
    }
    match scale {
        Scale::Linear if hi - lo < 1e-12 * lo.abs().max(1.0) => (lo - 0.5, hi + 0.5),
        Scale::Linear => {
            let pad = 0.05 * (hi - lo);
            (lo - pad, hi + pad)
        }
        Scale::Log10 => {
            let (a, b) = ((lo - 1e-9).floor(), (hi + 1e-9).ceil());
            if b > a {
                (a, b)
            } else {
                (a, a + 1.0)
            }
        }
    }
}

/// The ticks of an axis showing `lo..hi` (axis units), about `target` labelled ones on a
/// linear axis; on a log axis every decade (every second or more when there are many) is a
/// labelled major tick and 2…9 times a decade are minor ticks (when at most 8 decades show).
pub fn ticks(scale: Scale, lo: f64, hi: f64, target: usize) -> Vec<Tick> {
    let mut out = Vec::new();
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return out;
    }
    let eps = 1e-9 * (hi - lo);
    match scale {
        Scale::Linear => {
            let step = nice_step(hi - lo, target);
            let first = (lo / step).ceil() as i64;
            let last = (hi / step + 1e-9).floor() as i64;
            // At most a few hundred ticks whatever the range (the loop's budget).
            for k in first..=last.min(first + 400) {
                let at = k as f64 * step;
                out.push(Tick {
                    at,
                    label: fmt_tick(at, step),
                    major: true,
                });
            }
        }
        Scale::Log10 => {
            let (first, last) = ((lo - eps).ceil() as i32, (hi + eps).floor() as i32);
            let decades = (hi - lo).ceil().max(1.0) as i32;
            let every = (decades + target as i32 - 1) / (target as i32).max(1);
            let every = every.max(1);
            let minor = decades <= 8;
            for k in (lo.floor() as i32)..=(hi.ceil() as i32).min(lo.floor() as i32 + 400) {
                if (first..=last).contains(&k) {
                    out.push(Tick {
                        at: k as f64,
                        label: if k.rem_euclid(every) == 0 {
                            power_of_ten(k)
                        } else {
                            String::new()
                        },
                        major: true,
                    });
                }
                if minor {
                    for m in 2..=9 {
                        let at = k as f64 + (m as f64).log10();
                        if at > lo + eps && at < hi - eps {
                            out.push(Tick {
                                at,
                                label: String::new(),
                                major: false,
                            });
                        }
                    }
                }
            }
        }
    }
    out
}

/// Which edge of the plot area an axis is drawn along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// The bottom edge: the x axis.
    Bottom,
    /// The left edge: the y axis.
    Left,
}

/// The plot area in pixels: left, top, width and height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left edge \[px\].
    pub x: f64,
    /// Top edge \[px\].
    pub y: f64,
    /// Width \[px\].
    pub w: f64,
    /// Height \[px\].
    pub h: f64,
}

impl Rect {
    /// Whether the two rectangles share any point of positive area.
    #[cfg(test)]
    pub fn overlaps(&self, o: &Rect) -> bool {
        self.x < o.x + o.w && o.x < self.x + self.w && self.y < o.y + o.h && o.y < self.y + self.h
    }

    /// Whether the point lies inside (edges included).
    #[cfg(test)]
    pub fn contains(&self, (px, py): (f64, f64)) -> bool {
        px >= self.x && px <= self.x + self.w && py >= self.y && py <= self.y + self.h
    }
}

/// Writes `ticks` along `edge` of `area`, each at the pixel `to_px(tick.at)`: an outward tick
/// mark (longer for major ticks), a light grid line across the area for major ticks when `grid`,
/// and the label.
pub fn draw(
    o: &mut String,
    edge: Edge,
    area: Rect,
    ticks: &[Tick],
    to_px: impl Fn(f64) -> f64,
    grid: bool,
) {
    for t in ticks {
        let p = to_px(t.at);
        let len = if t.major { 5.0 } else { 3.0 };
        match edge {
            Edge::Bottom => {
                let b = area.y + area.h;
                if grid && t.major {
                    let _ = writeln!(
                        o,
                        r##"<line x1="{p:.1}" y1="{:.1}" x2="{p:.1}" y2="{b:.1}" stroke="#e4e4e4"/>"##,
                        area.y
                    );
                }
                let _ = writeln!(
                    o,
                    r##"<line x1="{p:.1}" y1="{b:.1}" x2="{p:.1}" y2="{:.1}" stroke="#333"/>"##,
                    b + len
                );
                if !t.label.is_empty() {
                    let _ = writeln!(
                        o,
                        r#"<text x="{p:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                        b + 19.0,
                        escape(&t.label)
                    );
                }
            }
            Edge::Left => {
                let l = area.x;
                if grid && t.major {
                    let _ = writeln!(
                        o,
                        r##"<line x1="{l:.1}" y1="{p:.1}" x2="{:.1}" y2="{p:.1}" stroke="#e4e4e4"/>"##,
                        area.x + area.w
                    );
                }
                let _ = writeln!(
                    o,
                    r##"<line x1="{:.1}" y1="{p:.1}" x2="{l:.1}" y2="{p:.1}" stroke="#333"/>"##,
                    l - len
                );
                if !t.label.is_empty() {
                    let _ = writeln!(
                        o,
                        r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
                        l - 8.0,
                        p + 4.5,
                        escape(&t.label)
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_are_labelled_decades_with_minor_ticks_between() {
        let (lo, hi) = padded_range(Scale::Log10, (3e-7f64).log10(), (4e-2f64).log10());
        assert_eq!((lo, hi), (-7.0, -1.0), "whole decades around the data");
        let t = ticks(Scale::Log10, lo, hi, 8);
        let majors: Vec<&Tick> = t.iter().filter(|t| t.major).collect();
        assert_eq!(majors.len(), 7);
        for m in &majors {
            assert_eq!(m.at, m.at.round(), "major ticks at decades: {}", m.at);
            assert_eq!(m.label, power_of_ten(m.at as i32));
        }
        assert_eq!(majors[0].label, "10⁻⁷");
        let minors = t.iter().filter(|t| !t.major).count();
        assert_eq!(minors, 6 * 8, "2…9 times each of the six full decades");
        assert!(t.iter().filter(|t| !t.major).all(|t| t.label.is_empty()));
        // Between 10⁻³ and 10⁻², the minor ticks sit at log10(2…9) past -3.
        let between: Vec<f64> = t
            .iter()
            .filter(|t| !t.major && t.at > -3.0 && t.at < -2.0)
            .map(|t| 10f64.powf(t.at + 3.0))
            .collect();
        for (k, v) in between.iter().enumerate() {
            assert!((v - (k + 2) as f64).abs() < 1e-9, "{v}");
        }
    }

    #[test]
    fn many_decades_label_every_few_and_drop_minor_ticks() {
        let t = ticks(Scale::Log10, -14.0, 2.0, 8);
        assert!(t.iter().all(|t| t.major));
        let labelled = t.iter().filter(|t| !t.label.is_empty()).count();
        assert!((6..=9).contains(&labelled), "{labelled}");
    }

    #[test]
    fn linear_ticks_are_nice_and_inside_the_range() {
        let t = ticks(Scale::Linear, -0.73, 0.41, 6);
        let at: Vec<f64> = t.iter().map(|t| t.at).collect();
        assert_eq!(at.len(), 6, "{at:?}");
        assert!(at.iter().all(|v| (-0.73..=0.41).contains(v)));
        let labels: Vec<&str> = t.iter().map(|t| t.label.as_str()).collect();
        assert_eq!(labels, ["−0.6", "−0.4", "−0.2", "0.0", "0.2", "0.4"]);
    }

    #[test]
    fn log_scale_leaves_out_what_it_cannot_show() {
        assert_eq!(Scale::Log10.to_axis(0.0), None);
        assert_eq!(Scale::Log10.to_axis(-1.0), None);
        assert_eq!(Scale::Log10.to_axis(1000.0), Some(3.0));
        assert_eq!(Scale::Linear.to_axis(f64::NAN), None);
    }
}
