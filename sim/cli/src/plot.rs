//! Small, dependency-free SVG line and scatter plots with labelled axes, ticks and a legend.

use std::fmt::Write as _;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Style {
    /// A polyline.
    Line,
    /// A dashed polyline.
    Dashed,
    /// Circles at the points.
    Circle,
    /// Stars at the points.
    Star,
    /// Small filled dots at the points (a scatter of many points, as in an orbit diagram).
    Dot,
}

/// One data series.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// `(x, y)` points.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
    /// CSS colour.
    pub color: &'static str,
}

/// A plot.
#[derive(Clone, Debug, Default)]
pub struct Plot {
    /// Title.
    pub title: String,
    /// x-axis label (with unit).
    pub x_label: String,
    /// y-axis label (with unit).
    pub y_label: String,
    /// Series.
    pub series: Vec<Series>,
    /// Same scale on both axes.
    pub equal_aspect: bool,
    /// Draw the unit circle.
    pub unit_circle: bool,
}

/// Colours for successive series.
pub const PALETTE: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

pub(crate) fn nice_step(span: f64, target: usize) -> f64 {
    let raw = span / target as f64;
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

pub(crate) fn fmt_tick(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let s = format!("{v:.decimals$}");
    if s == "-0" || s.chars().all(|c| c == '0' || c == '.' || c == '-') && s.starts_with('-') {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

/// A plot area: left and top margins, width and height [px].
pub(crate) struct Rect {
    pub ml: f64,
    pub mt: f64,
    pub pw: f64,
    pub ph: f64,
}

/// The plot area's frame and the two axis labels, for every figure.
pub(crate) fn frame(o: &mut String, r: Rect, height: f64, x_label: &str, y_label: &str) {
    let Rect { ml, mt, pw, ph } = r;
    let _ = write!(
        o,
        r##"<rect x="{ml}" y="{mt}" width="{pw}" height="{ph}" fill="none" stroke="#333"/>
<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>
<text transform="translate(18,{:.1}) rotate(-90)" text-anchor="middle">{}</text>
"##,
        ml + pw / 2.0,
        height - 16.0,
        escape(x_label),
        mt + ph / 2.0,
        escape(y_label)
    );
}

pub(crate) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

impl Plot {
    /// Renders the plot as an SVG document of `width` × `height` pixels.
    pub fn to_svg(&self, width: f64, height: f64) -> String {
        let (ml, mr, mt, mb) = (78.0, 24.0, 44.0, 62.0);
        let (pw, ph) = (width - ml - mr, height - mt - mb);
        let mut xs: Vec<f64> = Vec::new();
        let mut ys: Vec<f64> = Vec::new();
        for s in &self.series {
            for &(x, y) in &s.points {
                if x.is_finite() && y.is_finite() {
                    xs.push(x);
                    ys.push(y);
                }
            }
        }
        if self.unit_circle {
            xs.extend([-1.0, 1.0]);
            ys.extend([-1.0, 1.0]);
        }
        let range = |v: &[f64]| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if !lo.is_finite() {
                (0.0, 1.0)
            } else if hi - lo < 1e-12 {
                (lo - 0.5, hi + 0.5)
            } else {
                let pad = 0.05 * (hi - lo);
                (lo - pad, hi + pad)
            }
        };
        let (mut x0, mut x1) = range(&xs);
        let (mut y0, mut y1) = range(&ys);
        if self.equal_aspect {
            // Same metres (or units) per pixel on both axes.
            let sx = (x1 - x0) / pw;
            let sy = (y1 - y0) / ph;
            let s = sx.max(sy);
            let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            x0 = cx - 0.5 * s * pw;
            x1 = cx + 0.5 * s * pw;
            y0 = cy - 0.5 * s * ph;
            y1 = cy + 0.5 * s * ph;
        }
        let px = |x: f64| ml + (x - x0) / (x1 - x0) * pw;
        let py = |y: f64| mt + ph - (y - y0) / (y1 - y0) * ph;
        let mut o = String::new();
        let _ = write!(
            o,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Arial, sans-serif" font-size="13">
<rect width="100%" height="100%" fill="white"/>
<defs><clipPath id="plotarea"><rect x="{ml}" y="{mt}" width="{pw}" height="{ph}"/></clipPath></defs>
<text x="{}" y="26" text-anchor="middle" font-size="15" font-weight="bold">{}</text>
"#,
            ml + pw / 2.0,
            escape(&self.title)
        );
        // Grid and ticks.
        let xstep = nice_step(x1 - x0, 7);
        let ystep = nice_step(y1 - y0, 6);
        let mut t = (x0 / xstep).ceil() * xstep;
        while t <= x1 + 1e-12 {
            let x = px(t);
            let _ = writeln!(
                o,
                r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{:.1}" stroke="#e4e4e4"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
                mt + ph,
                mt + ph + 18.0,
                fmt_tick(t, xstep)
            );
            t += xstep;
        }
        let mut t = (y0 / ystep).ceil() * ystep;
        while t <= y1 + 1e-12 {
            let y = py(t);
            let _ = writeln!(
                o,
                r##"<line x1="{ml}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e4e4e4"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
                ml + pw,
                ml - 6.0,
                y + 4.0,
                fmt_tick(t, ystep)
            );
            t += ystep;
        }
        frame(
            &mut o,
            Rect { ml, mt, pw, ph },
            height,
            &self.x_label,
            &self.y_label,
        );
        let _ = writeln!(o, r#"<g clip-path="url(#plotarea)">"#);
        if self.unit_circle {
            let (cx, cy) = (px(0.0), py(0.0));
            let (rx, ry) = (px(1.0) - cx, cy - py(1.0));
            let _ = writeln!(
                o,
                r##"<ellipse cx="{cx:.1}" cy="{cy:.1}" rx="{rx:.1}" ry="{ry:.1}" fill="none" stroke="#555" stroke-dasharray="5,4"/><line x1="{ml}" y1="{cy:.1}" x2="{:.1}" y2="{cy:.1}" stroke="#999"/><line x1="{cx:.1}" y1="{mt}" x2="{cx:.1}" y2="{:.1}" stroke="#999"/>"##,
                ml + pw,
                mt + ph
            );
        }
        for s in &self.series {
            let pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .copied()
                .collect();
            match s.style {
                Style::Line | Style::Dashed => {
                    let d: Vec<String> = pts
                        .iter()
                        .map(|&(x, y)| format!("{:.2},{:.2}", px(x), py(y)))
                        .collect();
                    let dash = if s.style == Style::Dashed {
                        r#" stroke-dasharray="6,4""#
                    } else {
                        ""
                    };
                    let _ = writeln!(
                        o,
                        r#"<polyline fill="none" stroke="{}" stroke-width="1.8"{dash} points="{}"/>"#,
                        s.color,
                        d.join(" ")
                    );
                }
                Style::Circle => {
                    for &(x, y) in &pts {
                        let _ = writeln!(
                            o,
                            r#"<circle cx="{:.1}" cy="{:.1}" r="4.5" fill="none" stroke="{}" stroke-width="1.8"/>"#,
                            px(x),
                            py(y),
                            s.color
                        );
                    }
                }
                Style::Dot => {
                    for &(x, y) in &pts {
                        let _ = writeln!(
                            o,
                            r#"<circle cx="{:.1}" cy="{:.1}" r="1.3" fill="{}"/>"#,
                            px(x),
                            py(y),
                            s.color
                        );
                    }
                }
                Style::Star => {
                    for &(x, y) in &pts {
                        let _ = writeln!(
                            o,
                            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="20" fill="{}">*</text>"#,
                            px(x),
                            py(y) + 8.0,
                            s.color
                        );
                    }
                }
            }
        }
        let _ = writeln!(o, "</g>");
        // Legend, top right inside the plot area.
        let lw = 12.0
            + 7.5
                * self
                    .series
                    .iter()
                    .map(|s| s.label.chars().count())
                    .max()
                    .unwrap_or(0) as f64
            + 34.0;
        let lx = ml + pw - lw - 8.0;
        let ly = mt + 8.0;
        let _ = writeln!(
            o,
            r##"<rect x="{lx:.1}" y="{ly:.1}" width="{lw:.1}" height="{:.1}" fill="white" fill-opacity="0.85" stroke="#999"/>"##,
            8.0 + 18.0 * self.series.len() as f64
        );
        for (i, s) in self.series.iter().enumerate() {
            let y = ly + 16.0 + 18.0 * i as f64;
            let mark = match s.style {
                Style::Line => format!(
                    r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{}" stroke-width="2"/>"#,
                    lx + 6.0,
                    y - 4.0,
                    lx + 28.0,
                    y - 4.0,
                    s.color
                ),
                Style::Dashed => format!(
                    r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{}" stroke-width="2" stroke-dasharray="6,4"/>"#,
                    lx + 6.0,
                    y - 4.0,
                    lx + 28.0,
                    y - 4.0,
                    s.color
                ),
                Style::Circle => format!(
                    r#"<circle cx="{:.1}" cy="{:.1}" r="4.5" fill="none" stroke="{}" stroke-width="1.8"/>"#,
                    lx + 17.0,
                    y - 4.0,
                    s.color
                ),
                Style::Dot => format!(
                    r#"<circle cx="{:.1}" cy="{:.1}" r="3" fill="{}"/>"#,
                    lx + 17.0,
                    y - 4.0,
                    s.color
                ),
                Style::Star => format!(
                    r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="20" fill="{}">*</text>"#,
                    lx + 17.0,
                    y + 4.0,
                    s.color
                ),
            };
            let _ = writeln!(
                o,
                r#"{mark}<text x="{:.1}" y="{:.1}">{}</text>"#,
                lx + 34.0,
                y,
                escape(&s.label)
            );
        }
        o.push_str("</svg>\n");
        o
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svg_has_axes_labels_and_every_series() {
        let p = Plot {
            title: "t".into(),
            x_label: "time [s]".into(),
            y_label: "angle [rad]".into(),
            series: vec![
                Series {
                    label: "a".into(),
                    points: vec![(0.0, 0.0), (1.0, 2.0)],
                    style: Style::Line,
                    color: PALETTE[0],
                },
                Series {
                    label: "b".into(),
                    points: vec![(0.5, 1.0)],
                    style: Style::Star,
                    color: PALETTE[1],
                },
            ],
            equal_aspect: false,
            unit_circle: true,
        };
        let svg = p.to_svg(640.0, 480.0);
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("time [s]") && svg.contains("angle [rad]"));
        assert!(svg.contains("<polyline") && svg.contains(">*</text>") && svg.contains("<ellipse"));
    }
}
