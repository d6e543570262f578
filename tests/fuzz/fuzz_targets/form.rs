//! A form description (TOML) on any bytes: parsing and validation never panic, and a form that
//! is accepted writes itself back to TOML that reads back the same.
#![no_main]

use libfuzzer_sys::fuzz_target;
use form_description::FormDescription;

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let Ok(form) = FormDescription::from_toml_str(text) else { return };
    let again = FormDescription::from_toml_str(&form.to_toml_string());
    assert!(again.is_ok_and(|a| a == form), "the form does not read back");
});
