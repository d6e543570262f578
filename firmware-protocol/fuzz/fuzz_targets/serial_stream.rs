//! `serial::Decoder` on any byte stream, fed in chunks whose size the first byte picks.
//! Every frame it yields must re-encode to a frame that decodes to the same.
#![no_main]

use firmware_protocol::serial;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|input: &[u8]| {
    let Some((&chunk, stream)) = input.split_first() else { return };
    let mut decoder = serial::Decoder::new();
    for chunk in stream.chunks(usize::from(chunk).max(1)) {
        for frame in decoder.feed(chunk).flatten() {
            let again = serial::encode(&frame).expect("a decoded frame encodes");
            assert_eq!(serial::decode(&again[..again.len() - 1]), Ok(frame));
        }
    }
});
