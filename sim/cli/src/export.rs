//! Every figure written three ways, side by side: `NAME.svg` (as drawn), `NAME.png` (rendered
//! by resvg at [`PNG_SCALE`] times the SVG's size) and `NAME.pdf` (vector, by svg2pdf, the
//! text embedded as a font subset). The text is set in DejaVu Sans, vendored in `sim/cli/fonts/`
//! (subset, with its licence) and loaded from the binary, so a machine without system fonts
//! renders the same figures.

use crate::output::PathError;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use svg2pdf::usvg;

/// DejaVu Sans (subset; `sim/cli/fonts/LICENSE-DejaVu.txt`).
const FONT_REGULAR: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
/// DejaVu Sans Bold (subset), for the titles.
const FONT_BOLD: &[u8] = include_bytes!("../fonts/DejaVuSans-Bold.ttf");

/// Pixels of the PNG per SVG pixel (a 820 px wide figure becomes 1640 px: about 200 dpi at a
/// paper's column width).
pub const PNG_SCALE: f32 = 2.0;

/// A figure could not be written.
#[derive(Debug, thiserror::Error)]
pub enum FigureError {
    /// The figure's file could not be written.
    #[error(transparent)]
    Path(#[from] PathError),
    /// The SVG did not parse (a bug in the figure code: it names the file).
    #[error("figure `{file}`: the SVG does not parse: {source}")]
    Svg {
        /// The SVG file.
        file: String,
        /// The parser's error.
        #[source]
        source: usvg::Error,
    },
    /// The figure has no area to render.
    #[error("figure `{file}`: empty size {width} × {height} px")]
    Empty {
        /// The SVG file.
        file: String,
        /// Width \[px\].
        width: f32,
        /// Height \[px\].
        height: f32,
    },
    /// The PNG encoder failed.
    #[error("figure `{file}`: PNG encoding failed: {detail}")]
    Png {
        /// The PNG file.
        file: String,
        /// What the encoder said.
        detail: String,
    },
    /// The PDF conversion failed.
    #[error("figure `{file}`: PDF conversion failed: {detail}")]
    Pdf {
        /// The PDF file.
        file: String,
        /// What the converter said.
        detail: String,
    },
}

/// The parser options with the vendored fonts as the only fonts (loaded once).
fn options() -> &'static usvg::Options<'static> {
    static OPTIONS: OnceLock<usvg::Options<'static>> = OnceLock::new();
    OPTIONS.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(FONT_REGULAR.to_vec());
        db.load_font_data(FONT_BOLD.to_vec());
        db.set_sans_serif_family("DejaVu Sans");
        usvg::Options {
            font_family: "DejaVu Sans".into(),
            fontdb: Arc::new(db),
            ..usvg::Options::default()
        }
    })
}

/// The PNG and the PDF of the SVG document `svg` (`name` is for messages).
pub fn render(name: &str, svg: &str) -> Result<(Vec<u8>, Vec<u8>), FigureError> {
    let tree = usvg::Tree::from_str(svg, options()).map_err(|source| FigureError::Svg {
        file: name.to_string(),
        source,
    })?;
    let size = tree.size();
    let empty = || FigureError::Empty {
        file: name.to_string(),
        width: size.width(),
        height: size.height(),
    };
    let (w, h) = (
        (size.width() * PNG_SCALE).ceil(),
        (size.height() * PNG_SCALE).ceil(),
    );
    if !(w >= 1.0 && h >= 1.0 && w <= 20_000.0 && h <= 20_000.0) {
        return Err(empty());
    }
    let mut pixmap = resvg::tiny_skia::Pixmap::new(w as u32, h as u32).ok_or_else(empty)?;
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::from_scale(PNG_SCALE, PNG_SCALE),
        &mut pixmap.as_mut(),
    );
    let png = pixmap.encode_png().map_err(|e| FigureError::Png {
        file: name.to_string(),
        detail: e.to_string(),
    })?;
    let pdf = svg2pdf::to_pdf(
        &tree,
        svg2pdf::ConversionOptions::default(),
        svg2pdf::PageOptions::default(),
    )
    .map_err(|e| FigureError::Pdf {
        file: name.to_string(),
        detail: e.to_string(),
    })?;
    Ok((png, pdf))
}

/// Writes `dir/NAME.svg`, `dir/NAME.png` and `dir/NAME.pdf` from the SVG document `svg`; `flag`
/// is the option that named `dir` (for messages).
pub fn write_figure(
    flag: &'static str,
    dir: &Path,
    name: &str,
    svg: &str,
) -> Result<(), FigureError> {
    let write = |ext: &str, bytes: &[u8]| {
        let path = dir.join(format!("{name}.{ext}"));
        std::fs::write(&path, bytes).map_err(|e| PathError::new(flag, &path, e))
    };
    write("svg", svg.as_bytes())?;
    let (png, pdf) = render(&format!("{name}.svg"), svg)?;
    write("png", &png)?;
    write("pdf", &pdf)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::{Plot, Series, Style, PALETTE};

    fn figure() -> String {
        Plot {
            title: "swing hip angle over one step".into(),
            x_label: "time from heel strike (s)".into(),
            y_label: "swing hip angle (rad)".into(),
            series: vec![Series {
                label: "swing hip".into(),
                points: (0..50)
                    .map(|k| (k as f64 * 0.01, (k as f64 * 0.1).sin()))
                    .collect(),
                style: Style::LINE,
                color: PALETTE[0],
            }],
            ..Plot::default()
        }
        .to_svg(640.0, 400.0)
    }

    #[test]
    fn png_and_pdf_are_written_beside_the_svg_and_parse() {
        let dir = std::env::temp_dir().join(format!("walker-export-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        write_figure("--plot", &dir, "angles", &figure()).expect("written");
        let png = std::fs::read(dir.join("angles.png")).expect("png");
        let pdf = std::fs::read(dir.join("angles.pdf")).expect("pdf");
        let svg = std::fs::read_to_string(dir.join("angles.svg")).expect("svg");
        std::fs::remove_dir_all(&dir).expect("cleaned");
        assert!(svg.starts_with("<svg"));
        // PNG: signature, then IHDR with the scaled size.
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
        assert_eq!(&png[12..16], b"IHDR");
        assert_eq!((be(&png[16..20]), be(&png[20..24])), (1280, 800));
        // PDF: header, trailer, one page of the SVG's size in points, the font embedded.
        assert!(pdf.starts_with(b"%PDF-"));
        let tail = String::from_utf8_lossy(&pdf[pdf.len().saturating_sub(64)..]).to_string();
        assert!(tail.contains("%%EOF"), "{tail}");
        let text = String::from_utf8_lossy(&pdf);
        assert!(text.contains("/MediaBox [0 0 640 400]"), "page size");
        assert!(text.contains("DejaVu"), "the text's font is embedded");
    }

    #[test]
    fn the_text_is_rendered_into_the_png() {
        // The same figure with and without its text: the text must change pixels, i.e. the
        // vendored font was found and drawn (with no font, text silently draws nothing).
        let with_text = figure();
        let without = with_text
            .lines()
            .filter(|l| !l.contains("<text"))
            .collect::<Vec<_>>()
            .join("\n");
        let (a, _) = render("a", &with_text).expect("rendered");
        let (b, _) = render("b", &without).expect("rendered");
        assert!(a.len() > b.len() + 2000, "{} vs {} bytes", a.len(), b.len());
    }

    #[test]
    fn a_broken_svg_is_a_typed_error() {
        assert!(matches!(
            render("x.svg", "<svg"),
            Err(FigureError::Svg { .. })
        ));
    }
}
