//! `profiles.json` on any bytes: parsing never panics, and profiles that parse are fitted to
//! the reference form (what `dressform setpoints` does next) without panicking.
#![no_main]

use dressform::shape::profiles::Profiles;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|bytes: &[u8]| {
    let form = form_description::reference();
    let regions = dressform::form::form_fit::regions_of(&form);
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    if let Ok(profiles) = Profiles::parse(text, Path::new("fuzz.json"), &regions) {
        let _ = dressform::form::form_fit::fit(&profiles, &form);
    }
});
