//! Recognising files that are not meshes at all (an archive, UTF-16 text, an image...) or a
//! mesh in another format than its name says, by their first bytes, so that the message says
//! what the file is and what to do, instead of a parse error.

use super::Format;

/// What a file is, when it is plainly not a mesh in the format its name says: a sentence
/// naming the kind and what to do.
pub(super) fn not_a_mesh(bytes: &[u8], expected: Format) -> Option<String> {
    const KINDS: [(&[u8], &str, &str); 11] = [
        (b"\x1f\x8b", "a gzip file", "unpack it first (gunzip)"),
        (b"PK\x03\x04", "a zip archive", "unpack it first"),
        (b"PK\x05\x06", "an empty zip archive", "export the scan again"),
        (b"\xfd7zXZ\x00", "an xz file", "unpack it first (unxz)"),
        (b"BZh", "a bzip2 file", "unpack it first (bunzip2)"),
        (b"\x28\xb5\x2f\xfd", "a zstd file", "unpack it first (unzstd)"),
        (b"7z\xbc\xaf\x27\x1c", "a 7-Zip archive", "unpack it first"),
        (b"\x89PNG\r\n\x1a\n", "a PNG image", "export the scan as a mesh"),
        (b"\xff\xd8\xff", "a JPEG image", "export the scan as a mesh"),
        (b"GIF8", "a GIF image", "export the scan as a mesh"),
        (b"%PDF", "a PDF document", "export the scan as a mesh"),
    ];
    // A binary STL starts with 80 free bytes: its exact size is the better evidence.
    if expected == Format::Stl && super::stl::is_exact_binary(bytes) {
        return None;
    }
    let utf16 = bytes.starts_with(b"\xfe\xff")
        || bytes.starts_with(b"\xff\xfe")
        || (bytes.len() >= 8 && (0..4).all(|k| bytes[2 * k] != 0 && bytes[2 * k + 1] == 0));
    if utf16 {
        return Some("this is UTF-16 text; save it as UTF-8 or ASCII".into());
    }
    if let Some((_, kind, todo)) = KINDS.iter().find(|(magic, ..)| bytes.starts_with(magic)) {
        return Some(format!("this is {kind}; {todo}"));
    }
    let other = [(Format::Ply, &b"ply"[..]), (Format::Glb, b"glTF")]
        .into_iter()
        .find(|&(format, magic)| format != expected && bytes.starts_with(magic))
        .map(|(format, _)| format);
    let other = other.or_else(|| {
        let obj = bytes.starts_with(b"v ") || bytes.starts_with(b"# ");
        (expected != Format::Obj && expected != Format::Stl && obj).then_some(Format::Obj)
    });
    other.map(|format| {
        format!(
            "this file is in {format} format, not {expected}; rename it to .{}",
            format.extension()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn archives_images_and_utf16_are_named() {
        let utf16: Vec<u8> = "v 0 0 0\n".encode_utf16().flat_map(u16::to_le_bytes).collect();
        let cases: [(&[u8], &str); 5] = [
            (b"\x1f\x8b\x08\x00rest", "gzip file; unpack it first"),
            (b"PK\x03\x04rest", "zip archive"),
            (b"\x89PNG\r\n\x1a\n....", "PNG image"),
            (&utf16, "UTF-16"),
            (b"\xfe\xff\x00v", "UTF-16"),
        ];
        for (bytes, expected) in cases {
            let said = not_a_mesh(bytes, Format::Obj).unwrap_or_default();
            assert!(said.contains(expected), "{said}");
        }
    }

    #[test]
    fn a_mesh_in_another_format_is_named() {
        let said = not_a_mesh(b"ply\nformat ascii 1.0\n", Format::Obj).unwrap();
        assert_eq!(said, "this file is in PLY format, not OBJ; rename it to .ply");
        assert!(not_a_mesh(b"ply\n", Format::Ply).is_none());
        assert!(not_a_mesh(b"v 1 2 3\n", Format::Obj).is_none());
        assert!(not_a_mesh(b"solid x\n", Format::Stl).is_none());
    }
}
