use dressform::scan::{self, frame::FrameOptions};
use dressform::slice::sections;
fn main() {
    let scan = scan::load(std::path::Path::new("../shared/makehuman/base.obj"), &FrameOptions::default()).unwrap();
    let h = scan.frame.height_mm;
    let zs: Vec<f64> = (0..=80).map(|i| h * i as f64 / 80.0 + 0.5).collect();
    let t = std::time::Instant::now();
    let secs = sections(&scan.body, &zs);
    eprintln!("slice {:?}", t.elapsed());
    for s in secs {
        let desc: Vec<String> = s.loops.iter().map(|l| { let c = l.centroid(); format!("[c=({:.0},{:.0}) g={:.0} p={:.0} n={}]", c.x, c.y, l.tape_girth(), l.perimeter(), l.points.len()) }).collect();
        println!("z={:7.1} {}", s.height, desc.join(" "));
    }
}
