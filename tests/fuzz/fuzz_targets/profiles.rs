//! `profiles.json` on any bytes: parsing never panics, and profiles that parse are fitted to
//! the reference form (what `dressform setpoints` does next) without panicking.
#![no_main]

use dressform::profiles::Profiles;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|bytes: &[u8]| {
    if let Ok(profiles) = Profiles::from_json(bytes) {
        let _ = dressform::fitting::fit(&profiles, &sim::form::reference());
    }
});
