//! Writes a synthetic body as an ASCII OBJ so it can be looked at, and prints its ground truth.
//!
//! `cargo run --release -p capture-sim --example synthetic_body -- OUT.obj
//! [default|asymmetric|SEED|restSEED] [scanner]` — `restSEED` is the random customer SEED with
//! one arm lowered to rest on the torso (the left for an even seed), as the segmentation tests
//! pose it; `scanner` applies [`Artifacts::typical_scanner`] (metres, Y up, holes, noise).

use std::time::Instant;

use capture_sim::{Artifacts, BodyParams, Pose, capture, generate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args
        .next()
        .ok_or("usage: synthetic_body OUT.obj [default|asymmetric|SEED|restSEED] [scanner]")?;
    let params = match args.next().as_deref() {
        None | Some("default") => BodyParams::default(),
        Some("asymmetric") => {
            BodyParams { pose: Pose::asymmetric_example(), ..BodyParams::default() }
        }
        Some(rest) if rest.starts_with("rest") => {
            let seed: u64 = rest[4..].parse()?;
            BodyParams::random(seed).with_arm_resting_on_torso(seed.is_multiple_of(2))
        }
        Some(seed) => BodyParams::random(seed.parse()?),
    };
    let start = Instant::now();
    let body = generate(&params)?;
    eprintln!(
        "generated in {:.3} s: {} vertices, {} triangles",
        start.elapsed().as_secs_f64(),
        body.surface.positions.len(),
        body.surface.triangles.len()
    );
    eprintln!("{params:#?}\n{:#?}", body.truth);
    let surface = if args.next().as_deref() == Some("scanner") {
        capture(&body, &Artifacts::typical_scanner(1))
    } else {
        body.surface
    };
    let mut file = std::io::BufWriter::new(std::fs::File::create(&out)?);
    surface.write_obj(&mut file)?;
    Ok(())
}
