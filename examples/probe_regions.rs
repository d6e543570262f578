use dressform::regions::BodyRegions;
use dressform::scan::{self, frame::FrameOptions};
use dressform::slice::sections;
fn main() {
    let path = std::env::args().nth(1).unwrap_or("../shared/makehuman/base.obj".into());
    let scan = scan::load(std::path::Path::new(&path), &FrameOptions::default()).unwrap();
    let t = std::time::Instant::now();
    let r = BodyRegions::find(&scan.body, 5.0).unwrap();
    eprintln!("regions {:?}: {:?}", t.elapsed(), r.landmarks);
    let zs: Vec<f64> = (0..=40).map(|i| 40.0 * i as f64 + 10.0).collect();
    for s in sections(&scan.body, &zs) {
        let labels = r.label(&s);
        let d: Vec<String> = s.loops.iter().zip(&labels).map(|(l, r)| format!("{:?}:{:.0}", r, l.tape_girth())).collect();
        println!("{:6.0} {}", s.height, d.join(" "));
    }
}
