//! How the pictures go into the page so that it stands alone: a PNG as a `data:` URI (base64,
//! RFC 2397 and RFC 4648), an SVG inline, scalable to the page's width.

/// The base64 alphabet (RFC 4648, section 4, table 1).
const BASE64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
/// What pads the last group of a base64 text (RFC 4648, section 4).
const PAD: char = '=';

/// `bytes` in base64 (RFC 4648, section 4: padded, no line breaks).
fn base64(bytes: &[u8]) -> String {
    let mut text = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let byte = |k: usize| u32::from(chunk.get(k).copied().unwrap_or(0));
        let group = byte(0) << 16 | byte(1) << 8 | byte(2);
        // A chunk of n bytes gives n + 1 characters; the group of four is padded.
        for k in 0..4 {
            if k <= chunk.len() {
                text.push(char::from(BASE64[(group >> (18 - 6 * k) & 63) as usize]));
            } else {
                text.push(PAD);
            }
        }
    }
    text
}

/// A PNG file as a `data:` URI (RFC 2397), for an `<img>`'s `src`.
pub fn png_data_uri(png: &[u8]) -> String {
    format!("data:image/png;base64,{}", base64(png))
}

/// An SVG document as dressform writes it, ready to sit inside the page: any XML declaration
/// left out (it may only open a document), and a `viewBox` from its `width` and `height` where
/// it has none, so that the page's style can scale it to its width (without one, a narrower
/// box crops the drawing instead).
pub fn inline_svg(svg: &str) -> String {
    let svg = match svg.trim_start().strip_prefix("<?xml") {
        Some(rest) => rest.split_once("?>").map_or("", |(_, body)| body),
        None => svg,
    };
    let Some(open) = svg.find("<svg") else { return svg.to_string() };
    let tag_end = svg[open..].find('>').map_or(svg.len(), |end| open + end);
    let tag = &svg[open..tag_end];
    match (tag.contains("viewBox"), attribute(tag, "width"), attribute(tag, "height")) {
        (false, Some(width), Some(height)) => {
            let at = open + "<svg".len();
            format!("{} viewBox=\"0 0 {width} {height}\"{}", &svg[..at], &svg[at..])
        }
        _ => svg.to_string(),
    }
}

/// The value of the attribute `name` in the start tag `tag` (double-quoted, as dressform
/// writes them).
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    tag[start..].split('"').next()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RFC 4648, section 10's test vectors.
    #[test]
    fn base64_as_rfc_4648_gives_it() {
        let vectors = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, encoded) in vectors {
            assert_eq!(base64(plain.as_bytes()), encoded, "{plain:?}");
        }
        assert_eq!(base64(&[0xfb, 0xff, 0xbf]), "+/+/");
        assert_eq!(png_data_uri(b"foo"), "data:image/png;base64,Zm9v");
    }

    #[test]
    fn an_svg_inline_scales_with_the_page() {
        let svg =
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"1009\" height=\"343\"><g/></svg>";
        assert_eq!(
            inline_svg(svg),
            "<svg viewBox=\"0 0 1009 343\" xmlns=\"http://www.w3.org/2000/svg\" width=\"1009\" \
             height=\"343\"><g/></svg>"
        );
        let with_box = "<svg width=\"10\" height=\"5\" viewBox=\"0 0 10 5\"></svg>";
        assert_eq!(inline_svg(with_box), with_box);
        let declared = "<?xml version=\"1.0\"?>\n<svg viewBox=\"0 0 1 1\"/>";
        assert_eq!(inline_svg(declared), "\n<svg viewBox=\"0 0 1 1\"/>");
    }
}
