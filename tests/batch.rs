//! `dressform batch` and `batch-merge`: shards as separate processes (by --shard, by Slurm's
//! and by Kubernetes' variables) cover every scan once and merge to what one process makes;
//! a rerun skips everything; a failing scan is a row, not the end of the batch.

use crate::common::{coarse_scan, dressform};
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// The scans of customers 0..n written into `dir` (generated in parallel).
fn write_scans(dir: &Path, n: u64) {
    std::fs::create_dir_all(dir).unwrap();
    std::thread::scope(|s| {
        for k in 0..n {
            s.spawn(move || {
                std::fs::write(dir.join(format!("customer-{k:02}.ply")), coarse_scan(k)).unwrap()
            });
        }
    });
}

/// A summary's rows by customer, each a map from column to value, without `seconds`.
fn rows(path: &Path) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut reader =
        csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|record| {
            let record = record.unwrap();
            assert_eq!(record.len(), header.len(), "{record:?}");
            let row: BTreeMap<String, String> = header
                .iter()
                .zip(record.iter())
                .filter(|(h, _)| *h != "seconds")
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect();
            (row["customer"].clone(), row)
        })
        .collect()
}

/// `dressform batch` as a child process with `args` and the environment `env` (the shard
/// variables of this test's own environment removed).
fn batch(args: &[&str], env: &[(&str, &str)]) -> std::process::Child {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_dressform"));
    cmd.arg("batch").args(args);
    for var in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_STEP",
        "JOB_COMPLETION_INDEX",
    ] {
        cmd.env_remove(var);
    }
    cmd.envs(env.iter().copied());
    cmd.stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped());
    cmd.spawn().unwrap()
}

fn finished(child: std::process::Child, what: &str) -> String {
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(0), "{what}: {stderr}");
    stderr
}

#[test]
fn shards_cover_every_scan_once_and_merge_to_a_single_run_and_a_rerun_skips_all() {
    let tmp = tempfile::tempdir().unwrap();
    let scans = tmp.path().join("scans");
    write_scans(&scans, 12);
    let (scans_arg, sharded, single) =
        (scans.to_str().unwrap(), tmp.path().join("sharded"), tmp.path().join("single"));
    let out = sharded.to_str().unwrap();

    // Shard 1 by --shard, shard 2 as Slurm's array task 2 of --array=1-3, shard 3 as
    // Kubernetes' completion index 2 of 3: three processes at once.
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_STEP", "1"),
    ];
    let shards = [
        batch(&[scans_arg, "-o", out, "--shard", "1/3"], &[]),
        batch(&[scans_arg, "-o", out], &slurm),
        batch(&[scans_arg, "-o", out, "--shard-count", "3"], &[("JOB_COMPLETION_INDEX", "2")]),
    ];
    for (k, child) in shards.into_iter().enumerate() {
        let said = finished(child, &format!("shard {}", k + 1));
        assert!(said.contains(&format!("shard {}/3", k + 1)), "{said}");
    }
    let mut seen = BTreeMap::new();
    for k in 1..=3 {
        for customer in rows(&sharded.join(format!("summary-shard-{k}-of-3.csv"))).into_keys() {
            assert!(seen.insert(customer.clone(), k).is_none(), "{customer} in two shards");
        }
    }
    assert_eq!(seen.len(), 12, "{seen:?}");
    assert!((1..=3).all(|k| seen.values().any(|&s| s == k)), "a shard took nothing: {seen:?}");

    let merged = tmp.path().join("merged.csv");
    let (code, _, stderr) = dressform(&["batch-merge", out, "-o", merged.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");

    let one = batch(&[scans_arg, "-o", single.to_str().unwrap(), "--jobs", "2"], &[]);
    finished(one, "single run");
    let (merged, whole) = (rows(&merged), rows(&single.join("summary.csv")));
    assert_eq!(merged, whole);
    for (customer, row) in &whole {
        assert_eq!(row["status"], "done", "{customer}: {row:?}");
        for column in
            ["height_mm", "chest_mm", "waist_mm", "hip_mm", "stature_mm", "thigh_girth_mm_left"]
        {
            assert!(row[column].parse::<f64>().is_ok(), "{customer}: {column} in {row:?}");
        }
        let record = single.join(customer).join("intake.json");
        let record: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&record).unwrap()).unwrap();
        assert!(record["input_hash"].as_str().unwrap().starts_with("fnv1a64:"));
        assert!(single.join(customer).join("mannequin.obj").is_file());
        assert!(single.join(customer).join("setpoints.json").is_file());
    }

    // Again: every scan's outputs are there from the same input.
    let again = batch(&[scans_arg, "-o", single.to_str().unwrap()], &[]);
    finished(again, "rerun");
    let rerun = rows(&single.join("summary.csv"));
    for (customer, row) in &rerun {
        assert_eq!(row["status"], "skipped", "{customer}");
        let mut first = whole[customer].clone();
        first.insert("status".into(), "skipped".into());
        assert_eq!(row, &first);
    }

    // A customer in two summaries is refused.
    let shard1 = sharded.join("summary-shard-1-of-3.csv");
    let s1 = shard1.to_str().unwrap();
    let (code, _, stderr) = dressform(&["batch-merge", s1, s1, "-o", "/dev/null"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("is in") && stderr.lines().count() == 1, "{stderr}");
}

#[test]
fn a_manifest_names_units_and_a_failing_scan_does_not_stop_the_batch() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("good.ply"), coarse_scan(3)).unwrap();
    std::fs::write(dir.join("broken.ply"), b"ply\nformat ascii 1.0\nelement vertex 3\n").unwrap();
    // A good scan with a landmark file that has a bad line.
    std::fs::copy(dir.join("good.ply"), dir.join("marked.ply")).unwrap();
    std::fs::write(dir.join("marked.txt"), "sellion 0 1.6 0.1\nnavel 0 1.1\n").unwrap();
    let manifest = dir.join("manifest.csv");
    let listed =
        "path,customer,units,up\ngood.ply,alice,m,y\nbroken.ply,bob,,\nmarked.ply,carol,,\n";
    std::fs::write(&manifest, listed).unwrap();
    let out = dir.join("out");
    let (code, stdout, stderr) =
        dressform(&["batch", manifest.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{stdout}{stderr}");
    assert!(
        stderr.lines().last().unwrap().contains("2 of 3 scans could not be processed"),
        "{stderr}"
    );
    let summary = rows(&out.join("summary.csv"));
    assert_eq!(summary["alice"]["status"], "done");
    assert_eq!(summary["bob"]["status"], "failed");
    assert!(summary["bob"]["error"].contains("broken.ply"), "{:?}", summary["bob"]);
    let carol = &summary["carol"];
    assert!(carol["error"].contains("marked.txt line 2: expected 'name x y z'"), "{carol:?}");
    assert!(out.join("alice/mannequin.obj").is_file() && !out.join("bob").exists());

    // A bad manifest: one line naming the file, the line and the field.
    for (text, expected) in [
        ("path,customer,units\ngood.ply,alice,furlong\n", "line 2: units 'furlong' is not one of"),
        ("path,customer\ngood.ply,../x\n", "line 2: customer id '../x' contains a path separator"),
        ("file,who\ngood.ply,alice\n", "the header must name the columns path and customer"),
        ("path,customer\ngood.ply,a\nbroken.ply,a\n", "are both customer 'a'"),
    ] {
        std::fs::write(&manifest, text).unwrap();
        let (code, _, stderr) =
            dressform(&["batch", manifest.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_eq!(code, 2, "{text}: {stderr}");
        assert!(stderr.contains(expected) && stderr.lines().count() == 1, "{text}: {stderr}");
    }
}
