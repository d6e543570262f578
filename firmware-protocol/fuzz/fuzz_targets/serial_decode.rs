//! `serial::decode` on any bytes (one COBS frame without its delimiter). A frame that
//! decodes must re-encode to a frame that decodes to the same.
#![no_main]

use firmware_protocol::serial;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|encoded: &[u8]| {
    if let Ok(frame) = serial::decode(encoded) {
        let again = serial::encode(&frame).expect("a decoded frame encodes");
        assert_eq!(serial::decode(&again[..again.len() - 1]), Ok(frame));
    }
});
