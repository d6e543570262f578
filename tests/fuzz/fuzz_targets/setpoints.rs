//! A set-point file on any bytes: parsing, validating against the reference form and checking
//! the strokes never panic, and every checked target lies within its actuator's stroke.
#![no_main]

use dressform::form::setpoints::SetPoints;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let Ok(points) = SetPoints::from_json_str(text, Path::new("fuzz.json")) else { return };
    let form = form_description::reference();
    let _ = points.validate(&form);
    for clamp in [false, true] {
        if let Ok(checked) = points.check(&form, clamp) {
            for (id, target) in &checked.targets {
                let stroke = form.axis(id).expect("a checked id is the form's").stroke_mm;
                // Targets are in hundredths of a millimetre.
                let stroke = stroke + 0.005;
                let mm = target.mm();
                assert!((0.0..=stroke).contains(&mm), "{id}: {mm} outside 0..={stroke}");
            }
        }
    }
});
