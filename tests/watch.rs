//! `dressform watch`: scans copied in slowly (in place, or under a hidden name and renamed
//! in) and a broken one; the watcher killed (-9) mid-way and restarted, then interrupted
//! (SIGINT) with a scan in hand and restarted: every good scan processed once, the broken
//! one rejected with its reason, nothing missing.

use crate::common::coarse_scan;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// How long the test waits for the watcher at most: generous, for a loaded 2-core machine
/// (the test does not judge speed).
const PATIENCE: Duration = Duration::from_secs(900);
/// Chunks a scan is written in, and the pause after each: about 5 s a scan.
const CHUNKS: usize = 10;
const PAUSE: Duration = Duration::from_millis(500);
/// The settle time given to the watcher: well above the writers' pauses.
const SETTLE_S: &str = "8";

fn start_watcher(input: &Path, out: &Path, log: &Path) -> Child {
    let log = std::fs::OpenOptions::new().create(true).append(true).open(log).unwrap();
    Command::new(env!("CARGO_BIN_EXE_dressform"))
        .args(["watch", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--settle", SETTLE_S])
        .stdin(Stdio::null())
        .stdout(log.try_clone().unwrap())
        .stderr(log)
        .spawn()
        .unwrap()
}

/// The journal's events: (event, scan) pairs in order.
fn journal(out: &Path) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(out.join("journal.jsonl")).unwrap_or_default();
    text.lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .map(|v| {
            (v["event"].as_str().unwrap().to_string(), v["scan"].as_str().unwrap().to_string())
        })
        .collect()
}

/// How many scans the journal has ended (done or failed).
fn ended(out: &Path) -> usize {
    journal(out).iter().filter(|(e, _)| e != "started").count()
}

/// Waits until `until` holds, failing with the watcher's log after [`PATIENCE`] or when the
/// watcher ends.
fn wait(watcher: &mut Child, log: &Path, what: &str, until: impl Fn() -> bool) {
    let start = Instant::now();
    while !until() {
        let log = || std::fs::read_to_string(log).unwrap_or_default();
        if let Some(status) = watcher.try_wait().unwrap() {
            panic!("the watcher ended ({status}) before {what}:\n{}", log());
        }
        assert!(start.elapsed() < PATIENCE, "no {what} after {PATIENCE:?}:\n{}", log());
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Sends SIGINT to `watcher`, which must then end cleanly.
fn interrupt(watcher: &mut Child, log: &Path) {
    // SAFETY: kill(2) with the pid of our own child (not yet waited for) and a valid signal.
    assert_eq!(unsafe { libc::kill(watcher.id() as libc::pid_t, libc::SIGINT) }, 0);
    let status = watcher.wait().unwrap();
    let said = std::fs::read_to_string(log).unwrap_or_default();
    assert!(status.success() && said.ends_with("stopped\n"), "{status}: {said}");
}

/// Writes `bytes` to `path` in [`CHUNKS`] pieces with a pause after each; with `rename_to`,
/// under `path` (a hidden name), then renamed.
fn copy_slowly(bytes: &[u8], path: &Path, rename_to: Option<&Path>) {
    let mut file = std::fs::File::create(path).unwrap();
    for chunk in bytes.chunks(bytes.len().div_ceil(CHUNKS)) {
        file.write_all(chunk).unwrap();
        file.flush().unwrap();
        std::thread::sleep(PAUSE);
    }
    drop(file);
    if let Some(to) = rename_to {
        std::fs::rename(path, to).unwrap();
    }
}

#[test]
fn twenty_scans_copied_in_slowly_are_processed_once_across_a_kill_and_the_broken_one_rejected() {
    let tmp = tempfile::tempdir().unwrap();
    let (input, out, log) = (tmp.path().join("in"), tmp.path().join("out"), tmp.path().join("log"));
    std::fs::create_dir_all(&input).unwrap();
    // 19 scans and a broken one; customer 3 with a landmark file (SHARP's `name x y z`).
    let mut scans: Vec<(String, Vec<u8>)> = std::thread::scope(|s| {
        let made: Vec<_> = (0..19u64)
            .map(|k| s.spawn(move || (format!("customer-{k:02}.ply"), coarse_scan(k))))
            .collect();
        made.into_iter().map(|h| h.join().unwrap()).collect()
    });
    scans.push((
        "broken.ply".to_string(),
        b"ply\nformat ascii 1.0\nelement vertex 12\nend_header\n1 2".repeat(1000),
    ));
    std::fs::write(
        input.join("customer-03.txt"),
        "# SHARP\nsellion 0.0 1.55 0.1\nnavel nan nan nan\n",
    )
    .unwrap();

    let mut watcher = start_watcher(&input, &out, &log);
    // All copies at once: every third renamed in from a hidden name, the others in place.
    std::thread::scope(|s| {
        for (k, (name, bytes)) in scans.iter().enumerate() {
            let (input, name) = (&input, name.clone());
            s.spawn(move || match k % 3 {
                0 => copy_slowly(
                    bytes,
                    &input.join(format!(".{name}.part")),
                    Some(&input.join(&name)),
                ),
                _ => copy_slowly(bytes, &input.join(&name), None),
            });
        }
    });
    // Killed (-9) once a few scans are through, likely in the middle of one; restarted.
    wait(&mut watcher, &log, "five scans done", || ended(&out) >= 5);
    watcher.kill().unwrap();
    watcher.wait().unwrap();
    // Restarted; SIGINT while a scan is in hand: that scan is finished, then it stops.
    let mut watcher = start_watcher(&input, &out, &log);
    let in_hand = || {
        let events = journal(&out);
        ended(&out) >= 10 && events.last().is_some_and(|(e, _)| e == "started")
    };
    wait(&mut watcher, &log, "a tenth scan in hand", in_hand);
    interrupt(&mut watcher, &log);
    let last = journal(&out).pop().unwrap();
    assert_eq!(last.0, "done", "the scan in hand was not finished: {last:?}");
    // And once more, to the end.
    let mut watcher = start_watcher(&input, &out, &log);
    wait(&mut watcher, &log, "every scan ended", || ended(&out) >= 20);
    interrupt(&mut watcher, &log);
    let said = std::fs::read_to_string(&log).unwrap();

    let events = journal(&out);
    let mut done: BTreeMap<&str, usize> = BTreeMap::new();
    for (event, scan) in &events {
        if event == "done" {
            *done.entry(scan.as_str()).or_default() += 1;
        }
        assert!(event != "failed" || scan == "broken.ply", "{scan} failed: {said}");
    }
    assert_eq!(done.len(), 19, "{done:?}\n{said}");
    assert!(done.values().all(|&n| n == 1), "processed twice: {done:?}");
    for k in 0..19 {
        let dir = out.join(format!("customer-{k:02}"));
        assert!(dir.join("mannequin.obj").is_file() && dir.join("intake.json").is_file(), "{k}");
    }
    let landmarks: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("customer-03/landmarks.json")).unwrap())
            .unwrap();
    assert_eq!(landmarks["landmarks"].as_array().unwrap().len(), 2);

    let rejected: PathBuf = input.join("rejected");
    assert!(rejected.join("broken.ply").is_file() && !input.join("broken.ply").exists());
    let reason = std::fs::read_to_string(rejected.join("broken.ply.error.txt")).unwrap();
    assert!(reason.contains("What was seen: ") && reason.contains("What to do: "), "{reason}");
    assert!(!out.join("broken").exists());
    assert!(said.contains("broken: failed: "), "{said}");
}
