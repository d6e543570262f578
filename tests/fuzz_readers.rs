//! Fuzz-style property tests: no reader panics, whatever the bytes — random bytes, valid files
//! cut short, and valid files with bytes flipped. (Errors are fine; panics are not.)

use dressform::body::mesh::Mesh;
use dressform::body::scan::format::Format;
use glam::DVec3;
use proptest::prelude::*;

const FORMATS: [Format; 3] = [Format::Obj, Format::Ply, Format::Stl];

fn cube() -> Mesh {
    let p: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    Mesh::new(p, t)
}

/// Valid files of every kind we read, as seeds for mutation.
fn seeds() -> Vec<(Format, Vec<u8>)> {
    let mesh = cube();
    let ascii_ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                     element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let ascii_stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    vec![
        (Format::Obj, Format::Obj.encode(&mesh)),
        (Format::Ply, Format::Ply.encode(&mesh)),
        (Format::Ply, ascii_ply.as_bytes().to_vec()),
        (Format::Stl, Format::Stl.encode(&mesh)),
        (Format::Stl, ascii_stl.as_bytes().to_vec()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        for format in FORMATS {
            let _ = format.read(&bytes);
        }
    }

    #[test]
    fn truncated_files_never_panic(seed in 0usize..5, cut in 0.0f64..1.0) {
        let (format, bytes) = &seeds()[seed];
        let end = (bytes.len() as f64 * cut) as usize;
        let _ = format.read(&bytes[..end]);
    }

    #[test]
    fn corrupted_files_never_panic(
        seed in 0usize..5,
        flips in proptest::collection::vec((0.0f64..1.0, any::<u8>()), 1..8),
    ) {
        let (format, bytes) = &seeds()[seed];
        let mut bytes = bytes.clone();
        for (at, value) in flips {
            let i = ((bytes.len() - 1) as f64 * at) as usize;
            bytes[i] = value;
        }
        if let Ok(mesh) = format.read(&bytes) {
            // Whatever a reader accepts has every index in range.
            let n = mesh.positions.len() as u32;
            prop_assert!(mesh.triangles.iter().flatten().all(|&i| i < n));
            let _ = dressform::body::scan::from_mesh(mesh, std::path::Path::new("fuzz"), &Default::default());
        }
    }

    #[test]
    fn text_like_bytes_never_panic(text in "[ -~\n]{0,400}") {
        for format in FORMATS {
            let _ = format.read(text.as_bytes());
        }
        let _ = Format::Obj.read(format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{text}").as_bytes());
        let _ = Format::Ply.read(format!("ply\nformat ascii 1.0\n{text}").as_bytes());
    }
}
