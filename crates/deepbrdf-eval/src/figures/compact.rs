//! A compact form of the SVG that plotters writes, drawing the same picture in fewer bytes
//! (results folders are committed, and their charts were most of the repository). plotters
//! writes every element with its whole style: each point marker, tick and grid line repeats its
//! colour, opacity and width, and each label its font. Here each distinct style becomes one
//! class of a style sheet at the top, and elements name their class:
//!
//! - a run of consecutive opaque lines or polylines of one style becomes one `<path>` (opaque
//!   strokes of one colour paint the same pixels drawn together or one by one);
//! - a translucent one (the grid) becomes a `<path>` of its own, its opacity the stroke's, so
//!   each is blended on its own as before;
//! - circles (point markers) and texts keep their geometry and name their class.
//!
//! The painting order, every coordinate and every text are kept; other elements are copied as
//! they are. Compacting a compact SVG changes nothing.

use std::fmt::Write as _;

/// One element of the SVG: its tag, its attributes in order, the text inside (texts only) and
/// its source (copied when the element is not compacted).
struct Element<'a> {
    tag: &'a str,
    attrs: Vec<(&'a str, &'a str)>,
    content: Option<&'a str>,
    source: &'a str,
}

impl<'a> Element<'a> {
    fn get(&self, key: &str) -> Option<&'a str> {
        self.attrs.iter().find(|(k, _)| *k == key).map(|(_, v)| *v)
    }

    /// The attributes outside `geometry`: elements with the same style may share it.
    fn style(&self, geometry: &[&str]) -> Vec<(&'a str, &'a str)> {
        self.attrs.iter().filter(|(k, _)| !geometry.contains(k)).copied().collect()
    }
}

/// The attributes that place an element (kept on each element; the others are its style).
fn geometry(tag: &str) -> &'static [&'static str] {
    match tag {
        "line" => &["x1", "y1", "x2", "y2"],
        "polyline" => &["points"],
        "circle" => &["cx", "cy", "r"],
        "text" => &["x", "y", "dy", "transform"],
        _ => &[],
    }
}

/// Whether `e` is an element as plotters writes it, with its whole style (elements already
/// compacted lack it and are copied).
fn compactable(e: &Element) -> bool {
    let has = |keys: &[&str]| keys.iter().all(|k| e.get(k).is_some());
    match e.tag {
        "line" => has(&["x1", "y1", "x2", "y2", "stroke", "opacity"]),
        "polyline" => has(&["points", "stroke", "opacity"]) && e.get("fill") == Some("none"),
        "circle" => has(&["cx", "cy", "r", "fill", "opacity"]) && e.get("stroke") == Some("none"),
        "text" => has(&["x", "y", "font-family", "opacity"]) && e.content.is_some(),
        _ => false,
    }
}

/// `svg` (as plotters writes it) in the compact form of the module documentation.
pub fn compact_svg(svg: &str) -> String {
    let elements = parse(svg);
    let mut classes: Vec<Vec<(&str, String)>> = Vec::new();
    let mut body = String::with_capacity(svg.len() / 2);
    let mut i = 0;
    while i < elements.len() {
        let e = &elements[i];
        if !compactable(e) {
            body.push_str(e.source);
            body.push('\n');
            i += 1;
            continue;
        }
        let style = e.style(geometry(e.tag));
        let run = elements[i..]
            .iter()
            .take_while(|o| o.tag == e.tag && compactable(o) && o.style(geometry(o.tag)) == style)
            .count();
        let rule = css(e.tag, &style);
        let class = match classes.iter().position(|c| *c == rule) {
            Some(c) => c,
            None => {
                classes.push(rule);
                classes.len() - 1
            }
        };
        write_run(&mut body, &elements[i..i + run], &class_name(class));
        i += run;
    }
    if classes.is_empty() {
        return body;
    }
    // The style sheet goes right after the opening <svg> element.
    let open = body.find('\n').map_or(body.len(), |n| n + 1);
    let mut out = String::with_capacity(body.len() + 64 * classes.len());
    out.push_str(&body[..open]);
    out.push_str("<style>\n");
    for (c, rule) in classes.iter().enumerate() {
        let declarations: Vec<String> = rule.iter().map(|(k, v)| format!("{k}:{v}")).collect();
        let _ = writeln!(out, ".{}{{{}}}", class_name(c), declarations.join(";"));
    }
    out.push_str("</style>\n");
    out.push_str(&body[open..]);
    out
}

/// The CSS declarations of a `tag` element's `style` attributes: the same properties (a font
/// size in px, as CSS wants a unit where an SVG attribute does not), the element opacity as the
/// opacity of its stroke (lines) or fill (circles, texts), which paints the same for an element
/// painted by one of them only.
fn css<'a>(tag: &str, style: &[(&'a str, &'a str)]) -> Vec<(&'a str, String)> {
    let mut out = Vec::new();
    for &(k, v) in style {
        match k {
            "opacity" if v == "1" => {}
            "opacity" if matches!(tag, "line" | "polyline") => {
                out.push(("stroke-opacity", v.into()))
            }
            "opacity" => out.push(("fill-opacity", v.into())),
            "font-size" if v.parse::<f64>().is_ok() => out.push((k, format!("{v}px"))),
            _ => out.push((k, v.into())),
        }
    }
    if tag == "line" && !style.iter().any(|(k, _)| *k == "fill") {
        out.push(("fill", "none".into()));
    }
    out
}

/// The name of class number `c`: a, b, ..., z, ba, bb, ...
fn class_name(mut c: usize) -> String {
    let mut name = Vec::new();
    loop {
        name.push(b'a' + (c % 26) as u8);
        c /= 26;
        if c == 0 {
            break;
        }
    }
    name.reverse();
    String::from_utf8_lossy(&name).into_owned()
}

/// Writes a run of elements of one tag and one style, the class `class`.
fn write_run(out: &mut String, run: &[Element], class: &str) {
    let tag = run[0].tag;
    let opaque = run[0].get("opacity") == Some("1");
    match tag {
        "line" | "polyline" if opaque => {
            let d: String = run.iter().map(path_of).collect();
            let _ = writeln!(out, "<path class=\"{class}\" d=\"{d}\"/>");
        }
        "line" | "polyline" => run.iter().for_each(|e| {
            let _ = writeln!(out, "<path class=\"{class}\" d=\"{}\"/>", path_of(e));
        }),
        "circle" => run.iter().for_each(|e| {
            let at = |k| e.get(k).unwrap_or("0");
            let _ = writeln!(
                out,
                "<circle class=\"{class}\" cx=\"{}\" cy=\"{}\" r=\"{}\"/>",
                at("cx"),
                at("cy"),
                at("r")
            );
        }),
        _ => run.iter().for_each(|e| {
            let _ = write!(out, "<text class=\"{class}\"");
            for key in geometry("text") {
                if let Some(v) = e.get(key) {
                    let _ = write!(out, " {key}=\"{v}\"");
                }
            }
            let _ = writeln!(out, ">{}</text>", e.content.unwrap_or("").trim());
        }),
    }
}

/// The path data of a line or polyline: `M x y` then `L`, `H` or `V` to each next point.
fn path_of(e: &Element) -> String {
    let points: Vec<(&str, &str)> = match e.tag {
        "line" => vec![
            (e.get("x1").unwrap_or("0"), e.get("y1").unwrap_or("0")),
            (e.get("x2").unwrap_or("0"), e.get("y2").unwrap_or("0")),
        ],
        _ => e
            .get("points")
            .unwrap_or("")
            .split_whitespace()
            .filter_map(|p| p.split_once(','))
            .collect(),
    };
    let mut d = String::new();
    for (i, &(x, y)) in points.iter().enumerate() {
        match i {
            0 => {
                let _ = write!(d, "M{x} {y}");
            }
            _ if points[i - 1].0 == x => {
                let _ = write!(d, "V{y}");
            }
            _ if points[i - 1].1 == y => {
                let _ = write!(d, "H{x}");
            }
            _ => {
                let _ = write!(d, "L{x} {y}");
            }
        }
    }
    d
}

/// The elements of `svg`, one per tag at the top level: `<tag attrs/>`, `<tag attrs>` (the
/// opening `<svg>`, `<g>`), `</tag>`, and `<text attrs>content</text>` and `<style>` with its
/// content as one element.
fn parse(svg: &str) -> Vec<Element<'_>> {
    let mut out = Vec::new();
    let mut rest = svg.trim_start();
    while let Some(start) = rest.find('<') {
        rest = &rest[start..];
        let Some(end) = rest.find('>') else { break };
        let open = &rest[..=end];
        let body = open.trim_start_matches('<').trim_end_matches('>').trim_end_matches('/');
        let tag = body.split_whitespace().next().unwrap_or("");
        let attrs = attributes(&body[tag.len()..]);
        if matches!(tag, "text" | "style") && !open.ends_with("/>") {
            let closing = format!("</{tag}>");
            if let Some(close) = rest.find(&closing) {
                let source = &rest[..close + closing.len()];
                out.push(Element { tag, attrs, content: Some(&rest[end + 1..close]), source });
                rest = &rest[source.len()..];
                continue;
            }
        }
        out.push(Element { tag, attrs, content: None, source: open });
        rest = &rest[open.len()..];
    }
    out
}

/// The `key="value"` pairs of an opening tag's text after its name.
fn attributes(mut s: &str) -> Vec<(&str, &str)> {
    let mut out = Vec::new();
    while let Some(eq) = s.find("=\"") {
        let key = s[..eq].trim();
        let value_start = eq + 2;
        let Some(len) = s[value_start..].find('"') else { break };
        out.push((key, &s[value_start..value_start + len]));
        s = &s[value_start + len + 1..];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const PLOTTERS: &str = r##"<svg width="200" height="100" viewBox="0 0 200 100" xmlns="http://www.w3.org/2000/svg">
<rect x="0" y="0" width="200" height="100" opacity="1" fill="#FFFFFF" stroke="none"/>
<text x="100" y="5" dy="0.76em" text-anchor="middle" font-family="sans-serif" font-size="20.967741935483872" opacity="1" fill="#000000">
title &apos;a&apos;
</text>
<line opacity="0.12" stroke="#000000" stroke-width="1" x1="10" y1="90" x2="10" y2="10"/>
<line opacity="0.12" stroke="#000000" stroke-width="1" x1="10" y1="50" x2="190" y2="50"/>
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="1" points="5,90 10,90 "/>
<polyline fill="none" opacity="1" stroke="#000000" stroke-width="1" points="5,50 10,50 "/>
<polyline fill="none" opacity="1" stroke="#1F77B4" stroke-width="2" points="10,80 50,60 90,60 90,20 "/>
<circle cx="10" cy="80" r="3" opacity="1" fill="#1F77B4" stroke="none" stroke-width="1"/>
<circle cx="50" cy="60" r="3" opacity="1" fill="#1F77B4" stroke="none" stroke-width="1"/>
<text x="10" y="92" dy="0.76em" text-anchor="middle" font-family="sans-serif" font-size="9.6" opacity="1" fill="#000000" transform="rotate(90, 10, 92)">
red-plastic
</text>
<text x="50" y="92" dy="0.76em" text-anchor="middle" font-family="sans-serif" font-size="9.6" opacity="1" fill="#000000" transform="rotate(90, 50, 92)">
chrome
</text>
</svg>
"##;

    #[test]
    fn runs_share_their_style_and_the_picture_is_kept() {
        let compact = compact_svg(PLOTTERS);
        let expected = r##"<svg width="200" height="100" viewBox="0 0 200 100" xmlns="http://www.w3.org/2000/svg">
<style>
.a{text-anchor:middle;font-family:sans-serif;font-size:20.967741935483872px;fill:#000000}
.b{stroke-opacity:0.12;stroke:#000000;stroke-width:1;fill:none}
.c{fill:none;stroke:#000000;stroke-width:1}
.d{fill:none;stroke:#1F77B4;stroke-width:2}
.e{fill:#1F77B4;stroke:none;stroke-width:1}
.f{text-anchor:middle;font-family:sans-serif;font-size:9.6px;fill:#000000}
</style>
<rect x="0" y="0" width="200" height="100" opacity="1" fill="#FFFFFF" stroke="none"/>
<text class="a" x="100" y="5" dy="0.76em">title &apos;a&apos;</text>
<path class="b" d="M10 90V10"/>
<path class="b" d="M10 50H190"/>
<path class="c" d="M5 90H10M5 50H10"/>
<path class="d" d="M10 80L50 60H90V20"/>
<circle class="e" cx="10" cy="80" r="3"/>
<circle class="e" cx="50" cy="60" r="3"/>
<text class="f" x="10" y="92" dy="0.76em" transform="rotate(90, 10, 92)">red-plastic</text>
<text class="f" x="50" y="92" dy="0.76em" transform="rotate(90, 50, 92)">chrome</text>
</svg>
"##;
        assert_eq!(compact, expected);
        // Compacting again changes nothing.
        assert_eq!(compact_svg(&compact), compact);
    }
}
