//! Small, dependency-free SVG line and scatter plots for papers: labelled axes (linear or true
//! log axes, [`crate::axis`]), lines and markers drawn as shapes (never as font glyphs), the
//! legend outside the data area, optional equal (or stated) aspect, notes on the data.

use crate::axis::{self, Edge, Rect, Scale};
use crate::svg_text::escape;
use std::fmt::Write as _;

/// How the points of a series are joined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Line {
    /// Not joined.
    None,
    /// A solid polyline (a non-finite point breaks it).
    Solid,
    /// A dashed polyline (a non-finite point breaks it).
    Dashed,
}

/// The shape drawn at each point of a series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    /// Nothing.
    None,
    /// An open circle.
    Circle,
    /// A filled five-pointed star.
    Star,
    /// An open square.
    Square,
    /// A filled triangle.
    Triangle,
    /// An open diamond.
    Diamond,
    /// A small filled dot (a scatter of many points, as in an orbit diagram).
    Dot,
}

/// How a series is drawn: its line and its marker.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Style {
    /// The line joining the points.
    pub line: Line,
    /// The marker at each point.
    pub marker: Marker,
}

impl Style {
    /// A solid line.
    pub const LINE: Style = Style {
        line: Line::Solid,
        marker: Marker::None,
    };
    /// A dashed line.
    pub const DASHED: Style = Style {
        line: Line::Dashed,
        marker: Marker::None,
    };
    /// A solid line with a circle at every point (measured points joined).
    pub const LINE_CIRCLES: Style = Style {
        line: Line::Solid,
        marker: Marker::Circle,
    };

    /// Markers only.
    pub const fn markers(marker: Marker) -> Style {
        Style {
            line: Line::None,
            marker,
        }
    }
}

/// One data series.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text (a series with an empty label has no legend entry).
    pub label: String,
    /// `(x, y)` points in data units.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
    /// CSS colour.
    pub color: &'static str,
}

/// A short text at a data point (e.g. how many eigenvalues one marker stands for), offset by
/// `(dx, dy)` pixels from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Note {
    /// The point, in data units.
    pub at: (f64, f64),
    /// Offset of the text's start from the point \[px\] (y down).
    pub offset_px: (f64, f64),
    /// The text.
    pub text: String,
}

/// How the two axes' scales relate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Aspect {
    /// Each axis fills the plot area.
    #[default]
    Free,
    /// The y axis has `y_over_x` times the pixels per unit of the x axis: 1 for geometry drawn
    /// true to scale; more when a small sideways motion must be magnified (the figure must say
    /// so).
    Scaled {
        /// Pixels per y unit over pixels per x unit.
        y_over_x: f64,
    },
}

impl Aspect {
    /// True to scale.
    pub const EQUAL: Aspect = Aspect::Scaled { y_over_x: 1.0 };
}

/// A plot.
#[derive(Clone, Debug, Default)]
pub struct Plot {
    /// Title.
    pub title: String,
    /// A smaller line under the title (e.g. a stated magnification), if any.
    pub caption: Option<String>,
    /// x-axis label (with unit).
    pub x_label: String,
    /// y-axis label (with unit).
    pub y_label: String,
    /// x-axis scale.
    pub x_scale: Scale,
    /// y-axis scale.
    pub y_scale: Scale,
    /// Series.
    pub series: Vec<Series>,
    /// Notes at data points.
    pub notes: Vec<Note>,
    /// How the axes' scales relate.
    pub aspect: Aspect,
    /// Draw the unit circle (and the axes through the origin).
    pub unit_circle: bool,
}

/// Colours for successive series.
pub const PALETTE: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// Width of one legend or label character at the 13 px font size \[px\] (DejaVu Sans' mean
/// advance, slightly generous so that boxes never cut text).
const CHAR_PX: f64 = 7.6;
/// Height of one legend row \[px\].
const LEGEND_ROW_PX: f64 = 19.0;
/// Longest legend label (characters) still placed to the right of the plot area; longer ones
/// (or a legend taller than the plot area) go below it.
const RIGHT_LEGEND_MAX_CHARS: usize = 30;

/// Where a plot's parts go, in pixels, and the data ranges (axis units) its area shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// The data area.
    pub area: Rect,
    /// The legend box (outside the data area), if any series has a label.
    pub legend: Option<Rect>,
    /// x range shown (axis units: logarithms on a log axis).
    pub x_range: (f64, f64),
    /// y range shown (axis units).
    pub y_range: (f64, f64),
    /// Top of the x-axis label's baseline \[px\].
    pub x_label_y: f64,
}

impl Layout {
    /// The pixel of a data point, `None` if its scale cannot show it.
    pub fn pixel(&self, plot: &Plot, (x, y): (f64, f64)) -> Option<(f64, f64)> {
        let (ax, ay) = (plot.x_scale.to_axis(x)?, plot.y_scale.to_axis(y)?);
        Some((self.px_x(ax), self.px_y(ay)))
    }

    fn px_x(&self, ax: f64) -> f64 {
        let (x0, x1) = self.x_range;
        self.area.x + (ax - x0) / (x1 - x0) * self.area.w
    }

    fn px_y(&self, ay: f64) -> f64 {
        let (y0, y1) = self.y_range;
        self.area.y + self.area.h - (ay - y0) / (y1 - y0) * self.area.h
    }
}

/// The plot area's frame and the two axis labels, for every figure.
pub(crate) fn frame(o: &mut String, area: Rect, x_label_y: f64, x_label: &str, y_label: &str) {
    let Rect { x, y, w, h } = area;
    let _ = write!(
        o,
        r##"<rect x="{x:.1}" y="{y:.1}" width="{w:.1}" height="{h:.1}" fill="none" stroke="#333"/>
<text x="{:.1}" y="{x_label_y:.1}" text-anchor="middle">{}</text>
<text transform="translate(18,{:.1}) rotate(-90)" text-anchor="middle">{}</text>
"##,
        x + w / 2.0,
        escape(x_label),
        y + h / 2.0,
        escape(y_label)
    );
}

/// The opening of every figure's SVG document: size, font, white background, title and
/// optional caption, centred.
pub(crate) fn header(
    o: &mut String,
    (width, height): (f64, f64),
    title: &str,
    caption: Option<&str>,
) {
    let centre_x = width / 2.0;
    let _ = write!(
        o,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Arial, sans-serif" font-size="13">
<rect width="100%" height="100%" fill="white"/>
<text x="{centre_x:.1}" y="24" text-anchor="middle" font-size="15" font-weight="bold">{}</text>
"#,
        escape(title)
    );
    if let Some(c) = caption {
        let _ = writeln!(
            o,
            r##"<text x="{centre_x:.1}" y="42" text-anchor="middle" font-size="12" fill="#444">{}</text>"##,
            escape(c)
        );
    }
}

/// The SVG of `marker` centred at `(cx, cy)` \[px\].
pub(crate) fn marker_svg(marker: Marker, (cx, cy): (f64, f64), color: &str) -> String {
    let polygon = |pts: &[(f64, f64)], fill: bool| {
        let p: Vec<String> = pts
            .iter()
            .map(|(x, y)| format!("{:.1},{:.1}", cx + x, cy + y))
            .collect();
        if fill {
            format!(
                r#"<polygon points="{}" fill="{color}" stroke="{color}" stroke-width="0.8"/>"#,
                p.join(" ")
            )
        } else {
            format!(
                r#"<polygon points="{}" fill="white" fill-opacity="0.6" stroke="{color}" stroke-width="1.6"/>"#,
                p.join(" ")
            )
        }
    };
    match marker {
        Marker::None => String::new(),
        Marker::Circle => format!(
            r#"<circle cx="{cx:.1}" cy="{cy:.1}" r="4.2" fill="white" fill-opacity="0.6" stroke="{color}" stroke-width="1.6"/>"#
        ),
        Marker::Dot => format!(r#"<circle cx="{cx:.1}" cy="{cy:.1}" r="1.3" fill="{color}"/>"#),
        Marker::Star => {
            let pts: Vec<(f64, f64)> = (0..10)
                .map(|k| {
                    let r = if k % 2 == 0 { 5.8 } else { 2.4 };
                    let a = std::f64::consts::PI * (k as f64 / 5.0 - 0.5);
                    (r * a.cos(), r * a.sin())
                })
                .collect();
            polygon(&pts, true)
        }
        Marker::Square => polygon(&[(-4.0, -4.0), (4.0, -4.0), (4.0, 4.0), (-4.0, 4.0)], false),
        Marker::Triangle => polygon(&[(0.0, -5.5), (5.0, 3.5), (-5.0, 3.5)], true),
        Marker::Diamond => polygon(&[(0.0, -5.5), (5.0, 0.0), (0.0, 5.5), (-5.0, 0.0)], false),
    }
}

/// Pixels in x and y of a series' line, `None` for a line break (a point its scales cannot
/// show).
fn polylines(pts: &[Option<(f64, f64)>]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for p in pts {
        match (p, out.last_mut()) {
            (Some(p), Some(run)) => run.push(*p),
            (None, Some(run)) if !run.is_empty() => out.push(Vec::new()),
            _ => {}
        }
    }
    out.retain(|r| r.len() >= 2);
    out
}

impl Plot {
    fn labelled(&self) -> impl Iterator<Item = &Series> {
        self.series.iter().filter(|s| !s.label.is_empty())
    }

    /// Where everything goes in a `width` × `height` pixel figure.
    pub fn layout(&self, width: f64, height: f64) -> Layout {
        let top = if self.caption.is_some() { 58.0 } else { 42.0 };
        let (ml, mr, mb) = (80.0, 20.0, 58.0);
        let entries = self.labelled().count();
        let longest = self
            .labelled()
            .map(|s| s.label.chars().count())
            .max()
            .unwrap_or(0);
        let lw = 44.0 + CHAR_PX * longest as f64;
        let lh = 8.0 + LEGEND_ROW_PX * entries as f64;
        let right = entries > 0 && longest <= RIGHT_LEGEND_MAX_CHARS && lh <= height - top - mb;
        let (area, legend) = if entries == 0 {
            (
                Rect {
                    x: ml,
                    y: top,
                    w: width - ml - mr,
                    h: height - top - mb,
                },
                None,
            )
        } else if right {
            let w = width - ml - mr - lw - 14.0;
            (
                Rect {
                    x: ml,
                    y: top,
                    w,
                    h: height - top - mb,
                },
                Some(Rect {
                    x: ml + w + 14.0,
                    y: top,
                    w: lw,
                    h: lh,
                }),
            )
        } else {
            let h = height - top - mb - lh - 6.0;
            let w = width - ml - mr;
            (
                Rect {
                    x: ml,
                    y: top,
                    w,
                    h,
                },
                Some(Rect {
                    x: ml + (w - lw).max(0.0) / 2.0,
                    y: top + h + mb,
                    w: lw.min(width - ml),
                    h: lh,
                }),
            )
        };
        let (x_range, y_range) = self.ranges(area);
        Layout {
            area,
            legend,
            x_range,
            y_range,
            x_label_y: area.y + area.h + 44.0,
        }
    }

    /// The axis ranges for the data area `area`: the data (and the unit circle) padded, then
    /// widened on one axis to keep the aspect.
    fn ranges(&self, area: Rect) -> ((f64, f64), (f64, f64)) {
        let mut xs: Vec<f64> = Vec::new();
        let mut ys: Vec<f64> = Vec::new();
        for s in &self.series {
            for &(x, y) in &s.points {
                if let (Some(ax), Some(ay)) = (self.x_scale.to_axis(x), self.y_scale.to_axis(y)) {
                    xs.push(ax);
                    ys.push(ay);
                }
            }
        }
        if self.unit_circle {
            xs.extend([-1.0, 1.0]);
            ys.extend([-1.0, 1.0]);
        }
        let bounds = |v: &[f64]| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (lo, hi)
        };
        let (bx, by) = (bounds(&xs), bounds(&ys));
        let (mut x0, mut x1) = axis::padded_range(self.x_scale, bx.0, bx.1);
        let (mut y0, mut y1) = axis::padded_range(self.y_scale, by.0, by.1);
        if let Aspect::Scaled { y_over_x } = self.aspect {
            // Units per pixel along x: s; along y: s / y_over_x.
            let s = ((x1 - x0) / area.w).max((y1 - y0) / area.h * y_over_x);
            let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            x0 = cx - 0.5 * s * area.w;
            x1 = cx + 0.5 * s * area.w;
            y0 = cy - 0.5 * s / y_over_x * area.h;
            y1 = cy + 0.5 * s / y_over_x * area.h;
        }
        ((x0, x1), (y0, y1))
    }

    /// Renders the plot as an SVG document of `width` × `height` pixels.
    pub fn to_svg(&self, width: f64, height: f64) -> String {
        let l = self.layout(width, height);
        let area = l.area;
        let mut o = String::new();
        header(
            &mut o,
            (width, height),
            &self.title,
            self.caption.as_deref(),
        );
        let _ = writeln!(
            o,
            r#"<defs><clipPath id="plotarea"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}"/></clipPath></defs>"#,
            area.x, area.y, area.w, area.h
        );
        let x_ticks = axis::ticks(self.x_scale, l.x_range.0, l.x_range.1, 7);
        let y_ticks = axis::ticks(self.y_scale, l.y_range.0, l.y_range.1, 6);
        axis::draw(&mut o, Edge::Bottom, area, &x_ticks, |v| l.px_x(v), true);
        axis::draw(&mut o, Edge::Left, area, &y_ticks, |v| l.px_y(v), true);
        frame(&mut o, area, l.x_label_y, &self.x_label, &self.y_label);
        let _ = writeln!(o, r#"<g clip-path="url(#plotarea)">"#);
        if self.unit_circle {
            let (cx, cy) = (l.px_x(0.0), l.px_y(0.0));
            let (rx, ry) = (l.px_x(1.0) - cx, cy - l.px_y(1.0));
            let _ = writeln!(
                o,
                r##"<line x1="{:.1}" y1="{cy:.1}" x2="{:.1}" y2="{cy:.1}" stroke="#999"/><line x1="{cx:.1}" y1="{:.1}" x2="{cx:.1}" y2="{:.1}" stroke="#999"/><ellipse cx="{cx:.1}" cy="{cy:.1}" rx="{rx:.1}" ry="{ry:.1}" fill="none" stroke="#555" stroke-dasharray="5,4"/>"##,
                area.x,
                area.x + area.w,
                area.y,
                area.y + area.h
            );
        }
        for s in &self.series {
            let px: Vec<Option<(f64, f64)>> = s.points.iter().map(|&p| l.pixel(self, p)).collect();
            if s.style.line != Line::None {
                let dash = if s.style.line == Line::Dashed {
                    r#" stroke-dasharray="7,4""#
                } else {
                    ""
                };
                for run in polylines(&px) {
                    let d: Vec<String> =
                        run.iter().map(|(x, y)| format!("{x:.2},{y:.2}")).collect();
                    let _ = writeln!(
                        o,
                        r#"<polyline fill="none" stroke="{}" stroke-width="1.8" stroke-linejoin="round"{dash} points="{}"/>"#,
                        s.color,
                        d.join(" ")
                    );
                }
            }
            for p in px.iter().flatten() {
                let m = marker_svg(s.style.marker, *p, s.color);
                if !m.is_empty() {
                    let _ = writeln!(o, "{m}");
                }
            }
        }
        let _ = writeln!(o, "</g>");
        for n in &self.notes {
            if let Some((x, y)) = l.pixel(self, n.at) {
                let _ = writeln!(
                    o,
                    r##"<text x="{:.1}" y="{:.1}" font-size="12" fill="#222">{}</text>"##,
                    x + n.offset_px.0,
                    y + n.offset_px.1,
                    escape(&n.text)
                );
            }
        }
        if let Some(lg) = l.legend {
            self.legend(&mut o, lg);
        }
        o.push_str("</svg>\n");
        o
    }

    /// The legend in the box `lg`: each labelled series' line and marker, then its label.
    fn legend(&self, o: &mut String, lg: Rect) {
        let _ = writeln!(
            o,
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="white" stroke="#999"/>"##,
            lg.x, lg.y, lg.w, lg.h
        );
        for (i, s) in self.labelled().enumerate() {
            let y = lg.y + 4.0 + LEGEND_ROW_PX * (i as f64 + 0.5);
            if s.style.line != Line::None {
                let dash = if s.style.line == Line::Dashed {
                    r#" stroke-dasharray="7,4""#
                } else {
                    ""
                };
                let _ = writeln!(
                    o,
                    r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{}" stroke-width="2"{dash}/>"#,
                    lg.x + 6.0,
                    lg.x + 34.0,
                    s.color
                );
            }
            // A dot is drawn larger in the legend, to be seen.
            let m = match s.style.marker {
                Marker::Dot => format!(
                    r#"<circle cx="{:.1}" cy="{y:.1}" r="3" fill="{}"/>"#,
                    lg.x + 20.0,
                    s.color
                ),
                other => marker_svg(other, (lg.x + 20.0, y), s.color),
            };
            let _ = writeln!(
                o,
                r#"{m}<text x="{:.1}" y="{:.1}">{}</text>"#,
                lg.x + 40.0,
                y + 4.5,
                escape(&s.label)
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plot(labels: &[&str], aspect: Aspect) -> Plot {
        Plot {
            title: "t".into(),
            x_label: "time (s)".into(),
            y_label: "angle (rad)".into(),
            series: labels
                .iter()
                .enumerate()
                .map(|(i, l)| Series {
                    label: (*l).into(),
                    // Points reaching every corner of the data.
                    points: (0..=40)
                        .map(|k| {
                            let t = k as f64 / 40.0;
                            (10.0 * t, (i as f64 + 1.0) * (6.0 * t).sin())
                        })
                        .collect(),
                    style: Style::LINE,
                    color: PALETTE[i],
                })
                .collect(),
            aspect,
            ..Plot::default()
        }
    }

    #[test]
    fn svg_has_axes_labels_and_every_series_and_no_glyph_markers() {
        let mut p = plot(&["a"], Aspect::Free);
        p.series.push(Series {
            label: "b".into(),
            points: vec![(0.5, 1.0)],
            style: Style::markers(Marker::Star),
            color: PALETTE[1],
        });
        p.unit_circle = true;
        let svg = p.to_svg(640.0, 480.0);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("time (s)") && svg.contains("angle (rad)"));
        assert!(svg.contains("<polyline") && svg.contains("<polygon") && svg.contains("<ellipse"));
        assert!(!svg.contains(">*<"), "no literal asterisk as a marker");
    }

    #[test]
    fn the_legend_never_covers_a_plotted_point() {
        for labels in [
            &["stance ankle", "swing hip", "swing knee"][..],
            &["a walker with a long name (falls in step 5: fell forward)"][..],
        ] {
            for (w, h) in [(820.0, 480.0), (640.0, 600.0)] {
                let p = plot(labels, Aspect::Free);
                let l = p.layout(w, h);
                let lg = l.legend.expect("a legend");
                assert!(
                    !lg.overlaps(&l.area),
                    "legend {lg:?} on the data {:?}",
                    l.area
                );
                for s in &p.series {
                    for &pt in &s.points {
                        let px = l.pixel(&p, pt).expect("shown");
                        assert!(l.area.contains(px), "{px:?} outside {:?}", l.area);
                        assert!(!lg.contains(px), "{px:?} under the legend");
                    }
                }
                assert!(lg.x + lg.w <= w + 1e-9 && lg.y + lg.h <= h + 1e-9);
            }
        }
    }

    #[test]
    fn scaled_aspect_gives_the_stated_pixels_per_unit() {
        for f in [1.0, 5.0, 100.0] {
            let p = plot(&["path"], Aspect::Scaled { y_over_x: f });
            let l = p.layout(820.0, 420.0);
            let px_per_x = l.area.w / (l.x_range.1 - l.x_range.0);
            let px_per_y = l.area.h / (l.y_range.1 - l.y_range.0);
            assert!((px_per_y / px_per_x - f).abs() < 1e-9 * f, "{f}");
            for &pt in &p.series[0].points {
                assert!(l.area.contains(l.pixel(&p, pt).expect("shown")));
            }
        }
    }

    #[test]
    fn log_axes_place_decades_evenly_and_leave_out_non_positive_values() {
        let p = Plot {
            x_scale: Scale::Log10,
            y_scale: Scale::Log10,
            series: vec![Series {
                label: "rk4".into(),
                points: vec![(10.0, 1e-3), (100.0, 1e-5), (1000.0, 1e-7), (50.0, 0.0)],
                style: Style::LINE_CIRCLES,
                color: PALETTE[0],
            }],
            ..Plot::default()
        };
        let l = p.layout(720.0, 480.0);
        let a = l.pixel(&p, (10.0, 1e-3)).expect("shown");
        let b = l.pixel(&p, (100.0, 1e-5)).expect("shown");
        let c = l.pixel(&p, (1000.0, 1e-7)).expect("shown");
        assert!(((b.0 - a.0) - (c.0 - b.0)).abs() < 1e-9);
        assert!(((b.1 - a.1) - (c.1 - b.1)).abs() < 1e-9);
        assert_eq!(l.pixel(&p, (50.0, 0.0)), None);
        let svg = p.to_svg(720.0, 480.0);
        assert!(svg.contains(">10¹<") && svg.contains(">10⁻⁵<"));
        assert_eq!(
            svg.matches("<circle").count(),
            3 + 1,
            "a marker per point, one in the legend"
        );
    }

    #[test]
    fn a_non_finite_point_breaks_the_line() {
        let p = Plot {
            series: vec![Series {
                label: String::new(),
                points: vec![
                    (0.0, 0.0),
                    (1.0, 1.0),
                    (f64::NAN, f64::NAN),
                    (2.0, 0.0),
                    (3.0, 1.0),
                ],
                style: Style::DASHED,
                color: PALETTE[0],
            }],
            ..Plot::default()
        };
        let svg = p.to_svg(600.0, 400.0);
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(p.layout(600.0, 400.0).legend.is_none());
    }
}
