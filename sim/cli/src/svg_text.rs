//! Text inside an SVG figure: escaped once for every figure (the line plots, their axes and
//! the heat maps).

/// Text escaped for SVG.
pub(crate) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
