//! Garment fit testing (issue 30) on the simulated reference form shaped to a generated
//! customer: the shipped garments judged as described (ease, Laplace's law, the ring flagged),
//! a size sweep finding where each ring crosses the comfort limit, a panel over its force
//! limit stopping the test, and hosts and nodes of protocol 1.0 and 1.1 together.

// Drives the simulated form (the `simulator` feature).
#![cfg(feature = "simulator")]

use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::path::Path;
use std::sync::OnceLock;

use capture_sim::{BodyParams, generate};
use dressform::body::mesh::Mesh;
use dressform::body::scan::{self, frame::FrameOptions};
use dressform::form::controller::simulated::{SimConfig, SimulatedRig, drive_on_sim};
use dressform::form::controller::{
    Claim, DEFAULT_FORCE_WINDOW, DriveError, DriveOptions, DriveReport,
};
use dressform::form::fit_test::comfort::COMFORT_LIMIT_KPA;
use dressform::form::fit_test::sweep::{self, SweepStep};
use dressform::form::fit_test::{FitTest, Verdict, assess};
use dressform::form::form_fit::fit;
use dressform::form::setpoints::SetPoints;
use dressform::run::pipeline::symmetrize;
use dressform::shape::mannequin::MannequinOptions;
use dressform::shape::profiles::Profiles;
use firmware_protocol::drive::DriveState;
use firmware_protocol::version::PROTOCOL_1_0;
use form_description::garment::{GarmentSpec, shipped};
use form_description::{FormDescription, reference};
use form_sim::robot::SimOptions;
use glam::DVec3;

/// The default generated customer's set-points on the reference form (the demo's customer:
/// chest 960, waist 800, hip 1000 mm).
fn customer() -> &'static SetPoints {
    static SETPOINTS: OnceLock<SetPoints> = OnceLock::new();
    SETPOINTS.get_or_init(|| {
        let body = generate(&BodyParams::default()).unwrap();
        let mesh = Mesh::new(
            body.surface.positions.iter().map(|&p| DVec3::from_array(p)).collect(),
            body.surface.triangles,
        );
        let scan = scan::from_mesh(mesh, Path::new("customer"), &FrameOptions::default()).unwrap();
        let out = symmetrize(&scan, &MannequinOptions::default(), |_| {}).unwrap();
        let profiles = Profiles::of(&out.mannequin, &out.comparison.levels);
        fit(&profiles, &reference()).unwrap().setpoints()
    })
}

fn garment(form: &FormDescription, text: &str) -> GarmentSpec {
    GarmentSpec::from_toml_str(text, form).unwrap()
}

fn reading() -> DriveOptions {
    DriveOptions { read_forces: Some(DEFAULT_FORCE_WINDOW), ..DriveOptions::default() }
}

/// Shapes the simulated form wearing `garment` to `setpoints` and judges the garment.
async fn fit_test(form: &FormDescription, garment: &GarmentSpec, setpoints: &SetPoints) -> FitTest {
    let config = SimConfig::default().wearing(Some(garment.clone()));
    let (report, _) = drive_on_sim(form, setpoints, &reading(), &config, |_| {}).await.unwrap();
    assess(form, garment, &setpoints.target_girths_mm, &report.positions_mm, &report.forces)
}

/// Laplace's law for a band stretched over a round ring of the form's girth: `2π T / C`, kPa.
fn laplace_kpa(garment: &GarmentSpec, ring: &str, girth_mm: f64) -> f64 {
    let band = garment.bands.iter().find(|b| b.ring == ring).unwrap();
    let strain = (100.0 * (girth_mm - band.relaxed_girth_mm) / band.relaxed_girth_mm).max(0.0);
    TAU * band.stretch().tension(strain) / girth_mm
}

/// Every shipped garment on the customer's form: at every ring the ease is the description's
/// relaxed girth minus the form's girth within 1 mm, and a stretched band's mean pressure is
/// Laplace's within 5%; the fitted dress touches nothing, the one 5% too small at the waist is
/// flagged there and only there, the jersey top is comfortable or loose everywhere.
#[tokio::test(start_paused = true)]
async fn the_shipped_garments_fit_the_customer_as_described() {
    let form = reference();
    let setpoints = customer();
    for (name, text) in form_description::garment::SHIPPED {
        let garment = garment(&form, text);
        let fit = fit_test(&form, &garment, setpoints).await;
        assert_eq!(fit.rings.len(), garment.bands.len(), "{name}");
        for ring in &fit.rings {
            let ease = ring.ease_mm.unwrap();
            let on_form = ring.relaxed_girth_mm - ring.form_girth_mm;
            assert!(
                (ease - on_form).abs() <= 1.0,
                "{name} {}: ease {ease} vs {on_form}",
                ring.ring
            );
            let laplace = laplace_kpa(&garment, &ring.ring, ring.form_girth_mm);
            if laplace > 0.0 {
                let ratio = ring.mean_pressure_kpa / laplace;
                assert!(
                    (ratio - 1.0).abs() <= 0.05,
                    "{name} {}: {:.3} kPa vs Laplace's {laplace:.3}",
                    ring.ring,
                    ring.mean_pressure_kpa
                );
            } else {
                assert!(!ring.contact && ring.mean_pressure_kpa == 0.0, "{name} {ring:?}");
            }
        }
        let flagged: Vec<&str> = fit.flagged().map(|r| r.ring.as_str()).collect();
        match name {
            "woven-dress" => {
                assert!(fit.rings.iter().all(|r| r.verdict == Verdict::NoContact), "{fit:?}")
            }
            "woven-dress-small-waist" => assert_eq!(flagged, ["waist"], "{name}"),
            "jersey-top" => assert!(flagged.is_empty(), "{name}: {flagged:?}"),
            "compression-garment" => {
                let class = |r: &dressform::form::fit_test::RingFit| match r.verdict {
                    Verdict::Class(c) | Verdict::AboveClass(c) => c,
                    other => panic!("{}: {other:?}", r.ring),
                };
                let waist = fit.rings.iter().find(|r| r.ring == "waist").unwrap();
                assert!(fit.rings.iter().all(|r| class(r) <= class(waist)), "{fit:?}");
                assert!(class(waist) >= 2, "{waist:?}");
            }
            other => panic!("a shipped garment this test does not know: {other}"),
        }
    }
}

/// A firm jersey top (8% under the customer's girths, 22 N/m per %) swept over -40..+40 mm in
/// 5 mm steps: every ring's crossing of the 1.3 kPa comfort limit is found within one step of
/// where Laplace's law puts it, and the garment binds at the first ring to cross.
#[tokio::test(start_paused = true)]
async fn a_sweep_finds_where_each_ring_crosses_the_comfort_limit_within_one_step() {
    let form = reference();
    let base = customer();
    let mut text = String::from("name = \"firm jersey top\"\n");
    for ring in ["chest", "under-bust", "waist"] {
        let relaxed = (0.92 * base.target_girths_mm[ring]).round();
        text += &format!(
            "[[band]]\nring = \"{ring}\"\nrelaxed_girth_mm = {relaxed}\n\
             tension_n_per_m_per_percent = 22.0\n"
        );
    }
    let garment = garment(&form, &text);
    let range: sweep::SweepRange = "-40:40:5".parse().unwrap();
    let steps: Vec<SetPoints> =
        range.deltas().iter().map(|&d| sweep::step_setpoints(&form, &garment, base, d)).collect();
    let rig =
        SimulatedRig::start(&form, &SimConfig::default().wearing(Some(garment.clone()))).unwrap();
    let claim = Claim::take(rig.attach(), &form).await.unwrap();
    let reports: Vec<DriveReport> = claim.drive_through(&steps, &reading(), |_| {}).await.unwrap();
    assert_eq!(reports.len(), 17);
    let swept: Vec<SweepStep> = range
        .deltas()
        .into_iter()
        .zip(&reports)
        .map(|(delta_mm, r)| {
            let girths: BTreeMap<String, f64> =
                base.target_girths_mm.iter().map(|(k, g)| (k.clone(), g + delta_mm)).collect();
            let fit = assess(&form, &garment, &girths, &r.positions_mm, &r.forces);
            SweepStep { delta_mm, fit }
        })
        .collect();
    let result = sweep::analyse(swept, sweep::limit_for(garment.kind));
    assert_eq!(result.limit_kpa, COMFORT_LIMIT_KPA);
    assert!(result.saturated_mm.is_empty(), "{}", sweep::table(&result));
    assert_eq!(result.crossings.len(), 3, "{}", sweep::table(&result));
    for crossing in &result.crossings {
        let band = garment.bands.iter().find(|b| b.ring == crossing.ring).unwrap();
        // Laplace: 2π k 100 (C - C0) / (C0 C) = limit, so C = A C0 / (A - limit C0).
        let a = TAU * 22.0 * 100.0;
        let c0 = band.relaxed_girth_mm;
        let expected = a * c0 / (a - COMFORT_LIMIT_KPA * c0);
        assert!(
            (crossing.girth_mm - expected).abs() <= range.step_mm,
            "{}: crosses at {:.1} mm, Laplace's law at {expected:.1}\n{}",
            crossing.ring,
            crossing.girth_mm,
            sweep::table(&result)
        );
    }
    let binds = result.binds.as_ref().unwrap();
    assert!(result.crossings.iter().all(|c| c.delta_mm >= binds.delta_mm && !c.from_start));
    let [lo, hi] = result.usable_mm.unwrap();
    assert!(lo == -40.0 && hi < binds.delta_mm, "{lo}..{hi} vs {}", binds.delta_mm);
}

/// A rigid woven dress 5% too small at the waist (a poplin, 300 N/m per %): a waist panel
/// reaches its 50 N limit on the way out, stalls, and the drive stops naming it and the force.
#[tokio::test(start_paused = true)]
async fn a_panel_over_its_force_limit_stops_the_fit_test() {
    let form = reference();
    let text = shipped("woven-dress-small-waist").unwrap().replace("= 60.0", "= 300.0");
    let garment = garment(&form, &text);
    let config = SimConfig::default().wearing(Some(garment));
    let error = drive_on_sim(&form, customer(), &reading(), &config, |_| {}).await.unwrap_err();
    let message = error.to_string();
    assert!(message.contains("over its force limit") && message.contains("waist"), "{message}");
    assert!(message.contains("every node halted"), "{message}");
}

/// A 1.1 host with nodes of protocol 1.0: the form is shaped as before, and a fit test is
/// refused before anything moves, naming the nodes.
#[tokio::test(start_paused = true)]
async fn a_1_1_host_drives_1_0_nodes_and_refuses_to_read_forces_from_them() {
    let form = reference();
    let old = SimConfig {
        options: SimOptions { protocol: PROTOCOL_1_0, ..SimOptions::default() },
        ..SimConfig::default()
    };
    let (report, _) =
        drive_on_sim(&form, customer(), &DriveOptions::default(), &old, |_| {}).await.unwrap();
    assert!(report.converged() && report.forces.is_empty());
    let result = drive_on_sim(&form, customer(), &reading(), &old, |_| {}).await;
    let Err(dressform::form::controller::simulated::SimDriveError::Drive(DriveError::NoForce(
        nodes,
    ))) = result
    else {
        panic!("{result:?}")
    };
    assert_eq!(nodes, (1..=9).collect::<Vec<u8>>());
    let message = DriveError::NoForce(nodes).to_string();
    assert!(message.contains("protocol 1.0") && message.contains("1.1"), "{message}");
}

/// `dressform fit-test` end to end on a mannequin folder made by `symmetrize`: the dress too
/// small at the waist is flagged there only (JSON), `fit-test.json` and `fit.png` are written;
/// the same dress in a rigid poplin stalls a waist panel and the command fails with one line
/// naming it (exit 1); a garment naming a ring the form lacks is refused (exit 2).
#[test]
fn the_fit_test_command_reports_writes_its_files_and_stops_on_over_force() {
    let dir = tempfile::tempdir().unwrap();
    let scan = crate::common::synthetic_scan(dir.path(), 3);
    let mannequin = dir.path().join("mannequin");
    let path = |p: &Path| p.to_str().unwrap().to_string();
    let (code, _, stderr) =
        crate::common::dressform(&["symmetrize", &path(&scan), "-o", &path(&mannequin)]);
    assert_eq!(code, 0, "{stderr}");
    let out = dir.path().join("fit");
    let args = |garment: &str| {
        let mut args = vec!["fit-test".to_string(), garment.to_string(), "--sim".into()];
        args.extend(["--mannequin".into(), path(&mannequin), "--out".into(), path(&out)]);
        args
    };
    let run = |args: Vec<String>| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        crate::common::dressform(&args)
    };
    let mut json = args("woven-dress-small-waist");
    json.push("--json".into());
    let (code, stdout, stderr) = run(json);
    assert_eq!(code, 0, "{stderr}");
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    for ring in report["fit"]["rings"].as_array().unwrap() {
        let verdict = ring["verdict"].as_str().unwrap();
        let flagged = matches!(verdict, "critical" | "too-tight");
        assert_eq!(flagged, ring["ring"] == "waist", "{ring}");
    }
    let written: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("fit-test.json")).unwrap()).unwrap();
    assert_eq!(written, report);
    let png = image::open(out.join("fit.png")).unwrap();
    assert!(png.width() > 300 && png.height() > 200);

    let rigid = dir.path().join("rigid.toml");
    let text = shipped("woven-dress-small-waist").unwrap().replace("= 60.0", "= 300.0");
    std::fs::write(&rigid, text).unwrap();
    let (code, _, stderr) = run(args(&path(&rigid)));
    assert_eq!(code, 1, "{stderr}");
    let line = stderr.lines().find(|l| l.starts_with("error:")).unwrap();
    assert!(line.contains("over its force limit") && line.contains("waist"), "{stderr}");

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[[band]]\nring = \"knee\"\nrelaxed_girth_mm = 400\ntension_n_per_m_per_percent = 5\n").unwrap();
    let (code, _, stderr) = run(args(&path(&bad)));
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("bad.toml") && stderr.contains("no ring `knee`"), "{stderr}");
}

/// A form whose waist actuators ask for a 150 N limit, above the simulated actuators' rated
/// 100 N: refused before any node is enabled, naming the node, the limit and the rated force.
#[tokio::test(start_paused = true)]
async fn a_force_limit_above_the_rated_force_is_refused_before_anything_is_enabled() {
    let mut spec = reference().into_spec();
    for a in spec.actuators.iter_mut().filter(|a| a.ring == "waist") {
        a.force_limit_n = Some(150.0);
    }
    let form = FormDescription::try_from(spec).unwrap();
    let rig = SimulatedRig::start(&form, &SimConfig::default()).unwrap();
    let error = dressform::form::controller::drive(
        rig.attach(),
        &form,
        customer(),
        &DriveOptions::default(),
        |_| {},
    )
    .await
    .unwrap_err();
    let message = error.to_string();
    assert!(message.contains("force limit of 150 N, above its rated force of 100 N"), "{message}");
    let truth = rig.truth();
    assert!(truth.nodes.iter().all(|n| n.state == DriveState::Disabled), "{truth:?}");
}

/// A garment that presses a panel over its limit with the form at home: the node faults as it
/// is enabled; every node is stopped and disabled, and the error names the panel and force.
#[tokio::test(start_paused = true)]
async fn a_panel_over_its_limit_at_home_stops_every_node_as_they_are_enabled() {
    let form = reference();
    let text = "name = \"tiny\"\n[[band]]\nring = \"waist\"\nrelaxed_girth_mm = 400\n\
                tension_n_per_m_per_percent = 300\n";
    let config = SimConfig::default().wearing(Some(garment(&form, text)));
    let rig = SimulatedRig::start(&form, &config).unwrap();
    let error =
        dressform::form::controller::drive(rig.attach(), &form, customer(), &reading(), |_| {})
            .await
            .unwrap_err();
    let message = error.to_string();
    assert!(message.contains("waist-") && message.contains("over its force limit"), "{message}");
    let truth = rig.truth();
    let powered = |s: DriveState| matches!(s, DriveState::Enabled | DriveState::Homing);
    assert!(truth.nodes.iter().all(|n| !powered(n.state)), "{truth:?}");
}

/// A node that reboots while the forces are read voids the reading: the test fails saying so,
/// with every node stopped, rather than judging the garment on positions it lost.
#[tokio::test(start_paused = true)]
async fn a_node_rebooting_while_the_forces_are_read_voids_the_reading() {
    let form = reference();
    let garment = garment(&form, shipped("jersey-top").unwrap());
    let config = SimConfig { faults: "node4:reboot@15s".parse().unwrap(), ..SimConfig::default() }
        .wearing(Some(garment));
    let rig = SimulatedRig::start(&form, &config).unwrap();
    let long = DriveOptions { read_forces: Some(std::time::Duration::from_secs(20)), ..reading() };
    let error = dressform::form::controller::drive(rig.attach(), &form, customer(), &long, |_| {})
        .await
        .unwrap_err();
    let message = error.to_string();
    assert!(message.contains("node 4") && message.contains("reading is void"), "{message}");
    let truth = rig.truth();
    assert!(truth.nodes.iter().all(|n| n.state != DriveState::Enabled), "{truth:?}");
}
