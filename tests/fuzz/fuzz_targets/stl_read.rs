//! The STL reader on any bytes (see `mesh.rs` for what is checked).
#![no_main]

mod mesh;

use dressform::body::scan::format::Format;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| mesh::check(Format::Stl, bytes));
