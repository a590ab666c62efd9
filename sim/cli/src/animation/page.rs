//! The self-contained HTML page: the template, three.js (vendored from its npm package by
//! `scripts/vendor-three`, embedded at build time) and the drawing module inlined as text,
//! and the animation's data as JSON.

/// The page template (`{{NAME}}` placeholders).
const TEMPLATE: &str = include_str!("../../assets/animation/page.html");
/// The drawing module.
const APP_JS: &str = include_str!("../../assets/animation/app.js");
/// three.js: the parts the page uses, bundled and minified (`scripts/vendor-three`).
const THREE_JS: &str = include_str!("../../assets/three/three.bundle.min.js");
/// three.js's license, repeated in the page.
const THREE_LICENSE: &str = include_str!("../../assets/three/LICENSE");
/// The vendored three.js version (`scripts/vendor-three`).
pub const THREE_VERSION: &str = "0.187.0";

/// The page of `title` with the animation data `data_json`.
pub fn html(title: &str, data_json: &str) -> String {
    let title = escape_html(title);
    let data = data_json.replace("</", "<\\/");
    let three = script_text(THREE_JS);
    let app = script_text(APP_JS);
    let license = THREE_LICENSE.replace("--", "- -");
    fill(
        TEMPLATE,
        &[
            ("TITLE", &title),
            ("THREE_VERSION", THREE_VERSION),
            ("DATA", &data),
            ("THREE", &three),
            ("APP", &app),
            ("THREE_LICENSE", &license),
        ],
    )
}

/// `template` with each `{{NAME}}` replaced by its value, in one pass (a value is never
/// searched for placeholders); an unknown name stays as it is.
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out =
        String::with_capacity(template.len() + values.iter().map(|v| v.1.len()).sum::<usize>());
    let mut rest = template;
    while let Some(start) = rest.find("{{") {
        out.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        match after.find("}}").and_then(|end| {
            values
                .iter()
                .find(|(k, _)| *k == &after[..end])
                .map(|(_, v)| (end, v))
        }) {
            Some((end, v)) => {
                out.push_str(v);
                rest = &after[end + 2..];
            }
            None => {
                out.push_str("{{");
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// Script text that cannot end its `<script>` element early.
fn script_text(js: &str) -> String {
    js.replace("</script", "<\\/script")
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_placeholder_is_filled_and_scripts_stay_closed() {
        let page = html("a <b> & c", "{\"x\":\"</script>\"}");
        for key in [
            "TITLE",
            "THREE_VERSION",
            "DATA",
            "THREE",
            "APP",
            "THREE_LICENSE",
        ] {
            assert!(
                !page.contains(&format!("{{{{{key}}}}}")),
                "{key} left unfilled"
            );
        }
        assert!(page.contains("a &lt;b&gt; &amp; c"));
        // Exactly the template's own script elements end: none inside the inlined text.
        assert_eq!(
            page.matches("</script>").count(),
            TEMPLATE.matches("</script>").count()
        );
        assert!(!THREE_JS.contains("</script"), "the bundle needed escaping");
    }

    #[test]
    fn fill_is_one_pass() {
        assert_eq!(
            fill("{{A}}-{{B}}-{{C}}", &[("A", "{{B}}"), ("B", "2")]),
            "{{B}}-2-{{C}}"
        );
    }
}
