//! Checks on the SVG figures the service draws: every `<text>` must lie inside the view box.
//!
//! An SVG carries no font metrics, so a text's extent is estimated the way the figures lay
//! themselves out: [`EM_PER_CHAR`] of its font size a character (an upper bound for
//! sans-serif), one font size tall, placed by its `x`, `y`, `dy`, `text-anchor` and a
//! `rotate(...)` transform.

/// Width of one character as a share of the font size (railwear's figures lay out with it).
pub const EM_PER_CHAR: f64 = 0.6;

/// A `<text>` element: its content and estimated box `[left, top, right, bottom]`, px.
#[derive(Debug, Clone, PartialEq)]
pub struct TextBox {
    pub text: String,
    pub bounds: [f64; 4],
}

fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let at = tag.find(&key)? + key.len();
    tag[at..].split('"').next()
}

fn number(tag: &str, name: &str) -> Option<f64> {
    attribute(tag, name)?.trim_end_matches("px").parse().ok()
}

fn unescape(text: &str) -> String {
    text.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// The view box `(width, height)` of an SVG document (its `viewBox`, else width and height).
pub fn view_box(svg: &str) -> Option<(f64, f64)> {
    let start = svg.find("<svg")?;
    let tag = &svg[start..start + svg[start..].find('>')?];
    if let Some(vb) = attribute(tag, "viewBox") {
        let v: Vec<f64> = vb
            .split([' ', ','])
            .filter_map(|s| s.parse().ok())
            .collect();
        if v.len() == 4 {
            return Some((v[0] + v[2], v[1] + v[3]));
        }
    }
    Some((number(tag, "width")?, number(tag, "height")?))
}

/// Every `<text>` of `svg` with its estimated box.
pub fn text_boxes(svg: &str) -> Vec<TextBox> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(at) = rest.find("<text") {
        rest = &rest[at..];
        let Some(end_tag) = rest.find('>') else { break };
        let tag = &rest[..end_tag];
        let Some(close) = rest.find("</text>") else {
            break;
        };
        let text = unescape(rest[end_tag + 1..close].trim());
        rest = &rest[close..];
        let font = number(tag, "font-size").unwrap_or(16.0);
        let (x, y) = (
            number(tag, "x").unwrap_or(0.0),
            number(tag, "y").unwrap_or(0.0),
        );
        let width = EM_PER_CHAR * font * text.chars().count() as f64;
        // Along the text: where it starts relative to x.
        let along = match attribute(tag, "text-anchor") {
            Some("middle") => -0.5 * width,
            Some("end") => -width,
            _ => 0.0,
        };
        // Across: the top relative to y (baseline unless dy moves it).
        let across = match attribute(tag, "dy") {
            Some("0.76em") => 0.0,
            Some("0.5ex") => -0.5 * font,
            Some("-0.5ex") => -font,
            _ => -0.8 * font,
        };
        let rotation = attribute(tag, "transform")
            .and_then(|t| t.strip_prefix("rotate("))
            .and_then(|t| t.split([',', ' ', ')']).next())
            .and_then(|a| a.parse::<f64>().ok())
            .unwrap_or(0.0)
            .rem_euclid(360.0);
        let bounds = if (rotation - 270.0).abs() < 1e-9 {
            // Reads upwards: along the text is up the page, its top faces left.
            [x + across, y - along - width, x + across + font, y - along]
        } else if (rotation - 90.0).abs() < 1e-9 {
            [x - across - font, y + along, x - across, y + along + width]
        } else {
            [x + along, y + across, x + along + width, y + across + font]
        };
        out.push(TextBox { text, bounds });
    }
    out
}

/// The texts of `svg` that reach outside its view box (empty when all fit), described.
pub fn texts_outside_view_box(svg: &str) -> Vec<String> {
    let Some((width, height)) = view_box(svg) else {
        return vec!["no <svg> element with a size".into()];
    };
    text_boxes(svg)
        .into_iter()
        .filter(|t| {
            let [l, top, r, bottom] = t.bounds;
            l < -0.5 || top < -0.5 || r > width + 0.5 || bottom > height + 0.5
        })
        .map(|t| {
            format!(
                "{:?} at {:?} outside 0 0 {width} {height}",
                t.text, t.bounds
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_texts_that_stick_out() {
        let svg = r#"<svg width="100" height="50" viewBox="0 0 100 50"><text x="95" y="20" font-size="10">long label</text><text x="50" y="20" text-anchor="middle" font-size="10">ok</text></svg>"#;
        let out = texts_outside_view_box(svg);
        assert_eq!(out.len(), 1, "{out:?}");
        assert!(out[0].contains("long label"));
        let rotated = r#"<svg width="100" height="100"><text x="10" y="50" dy="0.76em" text-anchor="middle" font-size="10" transform="rotate(270, 10, 50)">a rotated label</text></svg>"#;
        assert!(texts_outside_view_box(rotated).is_empty());
    }
}
