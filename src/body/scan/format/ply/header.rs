//! The PLY header: the encoding, the elements with their counts and properties, the comments.
//! Lines end at `\n`, `\r\n` or `\r`, as in the text formats.

use super::super::ReadError;
use super::super::text::{shown, words};

/// How the payload is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Encoding {
    Ascii,
    Binary { big_endian: bool },
}

/// A PLY number type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Num {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Num {
    fn named(name: &[u8]) -> Option<Num> {
        Some(match name {
            b"char" | b"int8" => Num::I8,
            b"uchar" | b"uint8" => Num::U8,
            b"short" | b"int16" => Num::I16,
            b"ushort" | b"uint16" => Num::U16,
            b"int" | b"int32" => Num::I32,
            b"uint" | b"uint32" => Num::U32,
            b"float" | b"float32" => Num::F32,
            b"double" | b"float64" => Num::F64,
            _ => return None,
        })
    }

    /// Bytes in binary encodings.
    pub(super) fn size(self) -> usize {
        match self {
            Num::I8 | Num::U8 => 1,
            Num::I16 | Num::U16 => 2,
            Num::I32 | Num::U32 | Num::F32 => 4,
            Num::F64 => 8,
        }
    }

    pub(super) fn is_integer(self) -> bool {
        !matches!(self, Num::F32 | Num::F64)
    }
}

/// A property's type: one number, or a list of numbers preceded by its length.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Scalar(Num),
    List { length: Num, item: Num },
}

#[derive(Debug, Clone)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) kind: Kind,
}

#[derive(Debug, Clone)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: usize,
    pub(super) properties: Vec<Property>,
}

impl Element {
    /// The position of the property called `name`.
    pub(super) fn property(&self, name: &str) -> Option<usize> {
        self.properties.iter().position(|p| p.name == name)
    }

    /// The fewest bytes one item can take: binary, its scalars and list lengths; ASCII, one
    /// character and one separator per property.
    fn min_item_size(&self, encoding: Encoding) -> usize {
        match encoding {
            Encoding::Ascii => 2 * self.properties.len(),
            Encoding::Binary { .. } => {
                let size = |p: &Property| match p.kind {
                    Kind::Scalar(t) | Kind::List { length: t, .. } => t.size(),
                };
                self.properties.iter().map(size).sum()
            }
        }
    }

    /// The element's name as messages show it.
    pub(super) fn shown(&self) -> String {
        shown(self.name.as_bytes())
    }
}

#[derive(Debug, Clone)]
pub(super) struct Header {
    pub(super) encoding: Encoding,
    pub(super) elements: Vec<Element>,
    pub(super) comments: Vec<String>,
}

/// Parses the header at the start of `bytes`; returns it and the payload after it. Checks
/// that the payload can hold what the header declares (so that nothing is allocated beyond
/// what the file can fill).
pub(super) fn parse(bytes: &[u8]) -> Result<(Header, &[u8]), ReadError> {
    let mut at = 0;
    let mut number = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut comments = Vec::new();
    loop {
        if at == bytes.len() {
            return Err(ReadError::Malformed("the header has no end_header line".into()));
        }
        number += 1;
        let rest = &bytes[at..];
        let end = rest.iter().position(|&b| b == b'\n' || b == b'\r').unwrap_or(rest.len());
        let line = &rest[..end];
        at +=
            end + if rest[end..].starts_with(b"\r\n") { 2 } else { usize::from(end < rest.len()) };
        let mut w = words(line);
        let keyword = w.next().unwrap_or_default();
        if number == 1 {
            if keyword != b"ply" {
                return Err(ReadError::Malformed("the first line is not 'ply'".into()));
            }
            continue;
        }
        let bad = |problem: String| ReadError::at(number, problem);
        match keyword {
            b"format" => {
                encoding = Some(match w.next().unwrap_or_default() {
                    b"ascii" => Encoding::Ascii,
                    b"binary_little_endian" => Encoding::Binary { big_endian: false },
                    b"binary_big_endian" => Encoding::Binary { big_endian: true },
                    other => {
                        return Err(bad(format!(
                            "format {} is not ascii, binary_little_endian or binary_big_endian",
                            shown(other)
                        )));
                    }
                });
            }
            b"comment" => {
                let text = line.trim_ascii_start().strip_prefix(b"comment").unwrap_or_default();
                let text = text.strip_prefix(b" ").unwrap_or(text);
                comments.push(String::from_utf8_lossy(text).trim_end().to_string());
            }
            b"obj_info" | b"" => {}
            b"element" => {
                let (Some(name), Some(count)) = (w.next(), w.next()) else {
                    return Err(bad("an element needs a name and a count".into()));
                };
                let count = std::str::from_utf8(count)
                    .ok()
                    .and_then(|c| c.parse::<usize>().ok())
                    .ok_or_else(|| {
                    bad(format!("element count {} is not a count", shown(count)))
                })?;
                let name = String::from_utf8_lossy(name).into_owned();
                elements.push(Element { name, count, properties: Vec::new() });
            }
            b"property" => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| bad("a property before any element".into()))?;
                let kind = kind(&mut w).map_err(bad)?;
                let name = w.next().ok_or_else(|| bad("a property without a name".into()))?;
                let name = String::from_utf8_lossy(name).into_owned();
                element.properties.push(Property { name, kind });
            }
            b"end_header" => break,
            other => {
                return Err(bad(format!("{} is not a PLY header keyword", shown(other))));
            }
        }
    }
    let encoding = encoding.ok_or_else(|| ReadError::Malformed("no format line".into()))?;
    let header = Header { encoding, elements, comments };
    let payload = &bytes[at..];
    check_counts(&header, payload.len())?;
    Ok((header, payload))
}

/// The type after `property`: `TYPE` or `list LENGTH_TYPE ITEM_TYPE`.
fn kind<'a>(w: &mut impl Iterator<Item = &'a [u8]>) -> Result<Kind, String> {
    let first = w.next().unwrap_or_default();
    let num = |what: &str, name: Option<&[u8]>| {
        let name = name.unwrap_or_default();
        Num::named(name).ok_or_else(|| format!("{what} {} is not a PLY type", shown(name)))
    };
    if first != b"list" {
        return num("type", Some(first)).map(Kind::Scalar);
    }
    let length = num("list length type", w.next())?;
    let item = num("list item type", w.next())?;
    if !length.is_integer() {
        return Err("a list length must be an integer type".into());
    }
    Ok(Kind::List { length, item })
}

/// Refuses counts the payload cannot hold, and items without properties: a header may
/// declare billions of items in a few bytes.
fn check_counts(header: &Header, payload: usize) -> Result<(), ReadError> {
    let mut need: u128 = 0;
    for e in &header.elements {
        if e.count > 0 && e.properties.is_empty() {
            return Err(ReadError::Malformed(format!(
                "element {} declares {} items but has no properties",
                e.shown(),
                e.count
            )));
        }
        let least = e.count as u128 * e.min_item_size(header.encoding) as u128;
        need += least;
        if need > payload as u128 + 1 {
            return Err(ReadError::Truncated(format!(
                "element {} declares {} items (at least {least} bytes), but the data after the \
                 header is {payload} bytes",
                e.shown(),
                e.count
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_header_with_every_line_ending() {
        for eol in ["\n", "\r\n", "\r"] {
            let text = [
                "ply",
                "format ascii 1.0",
                "comment units: mm",
                "element vertex 1",
                "property float x",
                "property list uchar int idx",
                "end_header",
                "1 0",
            ]
            .join(eol);
            let (h, payload) = parse(text.as_bytes()).unwrap();
            assert_eq!(h.encoding, Encoding::Ascii);
            assert_eq!(h.comments, ["units: mm"]);
            assert_eq!(h.elements[0].count, 1);
            assert_eq!(
                h.elements[0].properties[1].kind,
                Kind::List { length: Num::U8, item: Num::I32 }
            );
            assert_eq!(payload, b"1 0");
        }
    }

    #[test]
    fn counts_beyond_the_data_and_empty_elements_are_refused() {
        let huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n";
        let e = parse(huge).unwrap_err().to_string();
        assert!(e.starts_with("truncated: element 'vertex' declares 4000000000 items"), "{e}");
        let empty = b"ply\nformat ascii 1.0\nelement junk 18446744073709551615\nend_header\n";
        let e = parse(empty).unwrap_err().to_string();
        assert!(
            e.contains("element 'junk' declares 18446744073709551615 items but has no properties"),
            "{e}"
        );
        let e =
            parse(b"ply\nformat ascii 1.0\nelement v -3\nend_header\n").unwrap_err().to_string();
        assert_eq!(e, "line 3: element count '-3' is not a count");
    }

    #[test]
    fn unknown_lines_are_named() {
        let e = parse(b"ply\nformat ascii 1.0\nelemnt vertex 3\n").unwrap_err().to_string();
        assert_eq!(e, "line 3: 'elemnt' is not a PLY header keyword");
        let e = parse(b"ply\nformat ascii 1.0\nelement v 1\nproperty flt x\nend_header\n");
        assert_eq!(e.unwrap_err().to_string(), "line 4: type 'flt' is not a PLY type");
    }
}
