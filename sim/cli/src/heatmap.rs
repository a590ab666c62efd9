//! A dependency-free SVG heat map of a grid with missing cells: coloured cells, one contour
//! line (linear interpolation, marching squares over the cell centres), hatched cells where
//! there is no value, a colour bar and labelled axes.

use crate::axis::{self, fmt_tick, nice_step, Edge, Rect, Scale};
use crate::plot::{frame, header};
use crate::svg_text::escape;
use std::fmt::Write as _;

/// A heat map: `z[j][i]` at `(x[i], y[j])`, `None` where there is no value.
#[derive(Clone, Debug, Default)]
pub struct HeatMap {
    /// Title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Colour-bar label.
    pub z_label: String,
    /// Cell centres along x.
    pub x: Vec<f64>,
    /// Cell centres along y.
    pub y: Vec<f64>,
    /// Values, one row per y.
    pub z: Vec<Vec<Option<f64>>>,
    /// The colour scale runs from `level − span` (blue) through `level` (white) to
    /// `level + span` (red), `span` the largest distance of a value from `level`; the contour
    /// is drawn at `level`.
    pub level: f64,
    /// Legend text of the contour.
    pub contour_label: String,
    /// Legend text of the cells without a value.
    pub missing_label: String,
}

/// Cell edges around centres `c` (midpoints; half a spacing beyond the ends).
fn edges(c: &[f64]) -> Vec<f64> {
    match c {
        [] => vec![0.0, 1.0],
        [v] => {
            let h = 0.05 * v.abs().max(1e-3);
            vec![v - h, v + h]
        }
        _ => {
            let mut e = Vec::with_capacity(c.len() + 1);
            e.push(c[0] - 0.5 * (c[1] - c[0]));
            e.extend(c.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            let n = c.len();
            e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
            e
        }
    }
}

/// Blue (`level − span` and below) → white (`level`) → red (`level + span` and above).
fn colour(v: f64, level: f64, span: f64) -> String {
    let t = (0.5 + 0.5 * (v - level) / span).clamp(0.0, 1.0);
    let (blue, red) = ((33.0, 102.0, 172.0), (178.0, 24.0, 43.0));
    let (a, b, s) = if t < 0.5 {
        (blue, (247.0, 247.0, 247.0), t / 0.5)
    } else {
        ((247.0, 247.0, 247.0), red, (t - 0.5) / 0.5)
    };
    let mix = |p: f64, q: f64| (p + (q - p) * s).round() as u8;
    format!(
        "#{:02x}{:02x}{:02x}",
        mix(a.0, b.0),
        mix(a.1, b.1),
        mix(a.2, b.2)
    )
}

/// The segments of the contour `z = level` through the cell centres (marching squares;
/// squares with a missing corner are skipped; a saddle is split by the square's mean).
pub fn contour(x: &[f64], y: &[f64], z: &[Vec<Option<f64>>], level: f64) -> Vec<[(f64, f64); 2]> {
    let mut out = Vec::new();
    for j in 0..y.len().saturating_sub(1) {
        for i in 0..x.len().saturating_sub(1) {
            let at = |jj: usize, ii: usize| z.get(jj).and_then(|r| r.get(ii)).copied().flatten();
            let (Some(a), Some(b), Some(c), Some(d)) =
                (at(j, i), at(j, i + 1), at(j + 1, i + 1), at(j + 1, i))
            else {
                continue;
            };
            // Corners counter-clockwise: (i,j), (i+1,j), (i+1,j+1), (i,j+1).
            let corners = [
                (x[i], y[j], a),
                (x[i + 1], y[j], b),
                (x[i + 1], y[j + 1], c),
                (x[i], y[j + 1], d),
            ];
            let mut cross = Vec::with_capacity(4);
            for k in 0..4 {
                let (p, q) = (corners[k], corners[(k + 1) % 4]);
                if (p.2 < level) != (q.2 < level) {
                    let t = (level - p.2) / (q.2 - p.2);
                    cross.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)));
                }
            }
            match cross.as_slice() {
                [p, q] => out.push([*p, *q]),
                [p, q, r, s] => {
                    // Saddle: corner 0 joins its neighbours' crossings if the mean is on its side.
                    let mean = 0.25 * (a + b + c + d);
                    if (mean < level) == (a < level) {
                        out.push([*p, *q]);
                        out.push([*r, *s]);
                    } else {
                        out.push([*q, *r]);
                        out.push([*s, *p]);
                    }
                }
                _ => {}
            }
        }
    }
    out
}

impl HeatMap {
    /// Renders the map as an SVG document of `width` × `height` pixels.
    pub fn to_svg(&self, width: f64, height: f64) -> String {
        let (ml, mr, mt, mb) = (86.0, 120.0, 64.0, 62.0);
        let colour_span = self
            .z
            .iter()
            .flatten()
            .flatten()
            .filter(|v| v.is_finite())
            .map(|v| (v - self.level).abs())
            .fold(1e-6 * self.level.abs().max(1.0), f64::max);
        let (pw, ph) = (width - ml - mr, height - mt - mb);
        let (ex, ey) = (edges(&self.x), edges(&self.y));
        let span = |e: &[f64]| {
            let lo = e.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = e.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if hi - lo > 0.0 {
                (lo, hi)
            } else {
                (lo - 0.5, lo + 0.5)
            }
        };
        let ((x0, x1), (y0, y1)) = (span(&ex), span(&ey));
        let px = |x: f64| ml + (x - x0) / (x1 - x0) * pw;
        let py = |y: f64| mt + ph - (y - y0) / (y1 - y0) * ph;
        let mut o = String::new();
        header(&mut o, (width, height), &self.title, None);
        let _ = writeln!(
            o,
            r##"<defs><pattern id="nogait" width="8" height="8" patternUnits="userSpaceOnUse" patternTransform="rotate(45)"><rect width="8" height="8" fill="#d0d0d0"/><line x1="0" y1="0" x2="0" y2="8" stroke="#8a8a8a" stroke-width="2"/></pattern></defs>"##
        );
        // Legend under the title: the contour and the missing cells.
        let _ = writeln!(
            o,
            r##"<line x1="{ml}" y1="42" x2="{:.1}" y2="42" stroke="black" stroke-width="2.5"/><text x="{:.1}" y="46">{}</text><rect x="{:.1}" y="34" width="22" height="14" fill="url(#nogait)" stroke="#777"/><text x="{:.1}" y="46">{}</text>"##,
            ml + 28.0,
            ml + 34.0,
            escape(&self.contour_label),
            ml + pw * 0.55,
            ml + pw * 0.55 + 28.0,
            escape(&self.missing_label)
        );
        for (j, row) in self.z.iter().enumerate() {
            for (i, v) in row.iter().enumerate() {
                let (Some(xa), Some(xb), Some(ya), Some(yb)) =
                    (ex.get(i), ex.get(i + 1), ey.get(j), ey.get(j + 1))
                else {
                    continue;
                };
                let (l, r) = (px(*xa).min(px(*xb)), px(*xa).max(px(*xb)));
                let (t, b) = (py(*ya).min(py(*yb)), py(*ya).max(py(*yb)));
                let fill = match v {
                    Some(v) if v.is_finite() => colour(*v, self.level, colour_span),
                    _ => "url(#nogait)".to_string(),
                };
                let _ = writeln!(
                    o,
                    r#"<rect x="{l:.2}" y="{t:.2}" width="{:.2}" height="{:.2}" fill="{fill}" shape-rendering="crispEdges"/>"#,
                    r - l + 0.3,
                    b - t + 0.3
                );
            }
        }
        for [p, q] in contour(&self.x, &self.y, &self.z, self.level) {
            let _ = writeln!(
                o,
                r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="black" stroke-width="2.5" stroke-linecap="round"/>"#,
                px(p.0),
                py(p.1),
                px(q.0),
                py(q.1)
            );
        }
        // Axes, ticks and labels.
        let area = Rect {
            x: ml,
            y: mt,
            w: pw,
            h: ph,
        };
        let x_ticks = axis::ticks(Scale::Linear, x0, x1, 7);
        let y_ticks = axis::ticks(Scale::Linear, y0, y1, 6);
        axis::draw(&mut o, Edge::Bottom, area, &x_ticks, px, false);
        axis::draw(&mut o, Edge::Left, area, &y_ticks, py, false);
        frame(&mut o, area, mt + ph + 44.0, &self.x_label, &self.y_label);
        // Colour bar: level − span to level + span.
        let (bx, bw) = (ml + pw + 24.0, 18.0);
        let steps = 40;
        let bar = |f: f64| self.level - colour_span + 2.0 * colour_span * f;
        for k in 0..steps {
            let v = bar((k as f64 + 0.5) / steps as f64);
            let y = mt + ph - ph * (k + 1) as f64 / steps as f64;
            let _ = writeln!(
                o,
                r#"<rect x="{bx:.1}" y="{y:.2}" width="{bw}" height="{:.2}" fill="{}"/>"#,
                ph / steps as f64 + 0.3,
                colour(v, self.level, colour_span)
            );
        }
        let tick = nice_step(colour_span, 2) / 10.0;
        for k in 0..=4 {
            let v = bar(k as f64 / 4.0);
            let y = mt + ph - ph * k as f64 / 4.0;
            let text = fmt_tick(v, tick);
            let _ = writeln!(
                o,
                r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#333"/><text x="{:.1}" y="{:.1}">{text}</text>"##,
                bx + bw,
                bx + bw + 4.0,
                bx + bw + 7.0,
                y + 4.0
            );
        }
        let _ = writeln!(
            o,
            r##"<rect x="{bx:.1}" y="{mt}" width="{bw}" height="{ph}" fill="none" stroke="#333"/><text transform="translate({:.1},{:.1}) rotate(-90)" text-anchor="middle">{}</text>"##,
            bx + bw + 60.0,
            mt + ph / 2.0,
            escape(&self.z_label)
        );
        o.push_str("</svg>\n");
        o
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_contour_passes_where_the_values_cross_the_level() {
        // z = x on a 3 × 2 grid: the level 1 is crossed at x = 1 on both rows.
        let x = [0.0, 0.5, 2.0];
        let y = [0.0, 1.0];
        let z = vec![
            vec![Some(0.0), Some(0.5), Some(2.0)],
            vec![Some(0.0), Some(0.5), Some(2.0)],
        ];
        let segs = contour(&x, &y, &z, 1.0);
        assert_eq!(segs.len(), 1);
        for (px, _) in segs[0] {
            assert!((px - 1.0).abs() < 1e-12, "{px}");
        }
        // A missing corner leaves its squares out.
        let mut holed = z.clone();
        holed[1][2] = None;
        assert!(contour(&x, &y, &holed, 1.0).is_empty());
    }

    #[test]
    fn svg_marks_missing_cells_and_draws_the_contour() {
        let h = HeatMap {
            title: "t".into(),
            x_label: "a".into(),
            y_label: "b".into(),
            z_label: "max |λ|".into(),
            x: vec![0.0, 1.0, 2.0],
            y: vec![0.0, 1.0],
            z: vec![
                vec![Some(0.5), Some(1.5), None],
                vec![Some(0.5), Some(1.5), Some(3.0)],
            ],
            level: 1.0,
            contour_label: "|λ| = 1".into(),
            missing_label: "no gait".into(),
        };
        let svg = h.to_svg(700.0, 500.0);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert_eq!(
            svg.matches(r#"fill="url(#nogait)""#).count(),
            2,
            "legend + one cell"
        );
        assert!(svg.contains(r#"stroke="black" stroke-width="2.5" stroke-linecap="round""#));
    }
}
