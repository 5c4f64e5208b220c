//! CLI tests of what happens around a run rather than inside it (issue 15): two runs on one
//! output folder, the lock of a killed run, a full disk and a read-only folder.
//!
//! The disk tests mount a small tmpfs inside a private user and mount namespace
//! (`unshare --user --map-root-user --mount`), so they need no privileges and leave no mount
//! behind; `unshare` and `mount` come with util-linux.

use crate::util;
use deepbrdf_data::merl::io::FILE_BYTES;
use std::path::Path;
use std::process::Command;

/// Runs `script` under `sh` in a private user and mount namespace; returns (status, stdout,
/// stderr).
fn in_namespace(script: &str) -> (bool, String, String) {
    let o = Command::new("unshare")
        .args(["--user", "--map-root-user", "--mount", "sh", "-c", script])
        .output()
        .expect("unshare (util-linux) must be installed");
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

#[test]
fn a_second_run_on_a_locked_folder_is_refused_and_a_stale_lock_is_taken_over() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let cache = s(&dir.path().join("cache"));
    std::fs::create_dir_all(&out).expect("mkdir");
    let lock = out.join(deepbrdf_data::lock::LOCK_FILE);
    // Another live process holds the folder's lock (util-linux flock takes the same flock(2)
    // lock the commands take; `-o`: only flock itself holds it, not its `sleep`, so killing
    // flock frees it as the death of a run would).
    let mut holder = Command::new("flock")
        .args(["-o", s(&lock).as_str(), "sleep", "60"])
        .spawn()
        .expect("flock (util-linux) must be installed");
    let t0 = std::time::Instant::now();
    while !lock.exists() && t0.elapsed().as_secs() < 10 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(200));
    let o = util::run(&["tabulate", "--material", "chrome", "--out", &s(&out), "--cache", &cache]);
    let _ = holder.kill();
    let _ = holder.wait();
    util::assert_clean_failure(&o, "another run is writing this folder");
    assert!(util::stderr(&o).contains(&s(&out)), "{}", util::stderr(&o));
    assert!(!out.join("chrome.binary").exists(), "the refused run wrote nothing");

    // The holder is dead (killed): its lock file is still there, and the next run takes over.
    assert!(lock.exists());
    std::fs::write(&lock, "pid 999999999\ncommand experiments tabulate\n").expect("write");
    let o = util::run(&["tabulate", "--material", "chrome", "--out", &s(&out), "--cache", &cache]);
    assert!(o.status.success(), "{}", util::stderr(&o));
    assert_eq!(
        std::fs::metadata(out.join("chrome.binary")).expect("written").len(),
        FILE_BYTES as u64
    );
}

#[test]
fn a_full_disk_and_a_read_only_folder_give_clear_errors_and_keep_what_was_there() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mnt = dir.path().join("mnt");
    std::fs::create_dir_all(&mnt).expect("mkdir");
    let cache = s(&dir.path().join("cache"));
    let exe = env!("CARGO_BIN_EXE_experiments");
    let (m, d) = (s(&mnt), s(dir.path()));
    // 40 MiB hold one MERL file (35 MB) but not a second one, nor a temporary copy beside it.
    let script = format!(
        "set -u; mount -t tmpfs -o size=40m tmpfs {m} || exit 90
         {exe} tabulate --material chrome --out {m}/out --cache {cache} --quiet || exit 91
         mv {m}/out/chrome.binary {m}/out/steel.binary
         cp {m}/out/steel.binary {d}/before.binary
         echo '== new file'
         {exe} tabulate --material gold-metallic-paint --out {m}/out --cache {cache} --quiet; echo rc=$?
         echo '== replacing a file'
         {exe} tabulate --material steel --out {m}/out --cache {cache} --force --quiet; echo rc=$?
         echo '== listing'; ls -A {m}/out
         cp {m}/out/steel.binary {d}/after.binary
         mount -o remount,ro {m} || exit 92
         echo '== read-only'
         {exe} tabulate --material chrome --out {m}/out2 --cache {cache} --quiet; echo rc=$?
         exit 0"
    );
    let (ok, out, err) = in_namespace(&script);
    assert!(ok, "namespace script failed: {out}\n{err}");
    assert!(!err.contains("panicked"), "{err}");
    let sections: Vec<&str> = out.split("== ").collect();
    let section = |name: &str| sections.iter().find(|s| s.starts_with(name)).copied().unwrap_or("");
    // Both writes on the full disk failed with an exit code, not a crash.
    for name in ["new file", "replacing a file"] {
        assert!(section(name).contains("rc=1"), "{name}: {out}\n{err}");
    }
    assert!(err.matches("No space left on device").count() >= 2, "{err}");
    assert!(err.contains("gold-metallic-paint.binary") || err.contains(&m), "{err}");
    // Nothing half-written is left under a final name or as a temporary file.
    let listing = section("listing");
    assert!(listing.contains("steel.binary"), "{listing}");
    assert!(!listing.contains("gold-metallic-paint.binary"), "{listing}");
    assert!(!listing.contains(".tmp"), "{listing}");
    // The file that was there is intact, byte for byte.
    let before = std::fs::read(dir.path().join("before.binary")).expect("before");
    let after = std::fs::read(dir.path().join("after.binary")).expect("after");
    assert_eq!(before.len(), FILE_BYTES);
    assert!(before == after, "the replaced-on-a-full-disk file changed");
    // A read-only folder: an error that names it.
    assert!(section("read-only").contains("rc=1"), "{out}\n{err}");
    assert!(err.contains("Read-only file system"), "{err}");
    assert!(err.contains("out2"), "{err}");
}

/// Trials of the kill test: [`KILL_TRIALS_VAR`] if set (the reliability table in the README was
/// measured with 20), else 2 (CI).
const KILL_TRIALS_VAR: &str = "DEEPBRDF_KILL_TRIALS";

/// The bytes a finished training run leaves that must not depend on how often it was killed.
fn run_outputs(run: &Path) -> Vec<(String, Vec<u8>)> {
    ["model/weights.bpk", "model/basis.f16", "train_log.csv"]
        .iter()
        .map(|f| (f.to_string(), std::fs::read(run.join(f)).unwrap_or_default()))
        .collect()
}

#[test]
fn train_killed_at_random_moments_resumes_to_bit_identical_weights() {
    use deepbrdf_model::burn::config::Config as _;
    use deepbrdf_model::{AutoencoderConfig, TrainConfig};
    use rand::{Rng, SeedableRng};
    use std::time::{Duration, Instant};

    let dir = tempfile::tempdir().expect("tempdir");
    let data = util::write_data(dir.path(), 3);
    // The cpu preset's kind of network, tiny; a checkpoint after every batch, so kills land in
    // epochs, in checkpoint writes and in the final save alike.
    let mut config =
        TrainConfig::cpu(2).with_epochs(60).with_batch_size(1).with_checkpoint_seconds(0.0);
    config.model = AutoencoderConfig::spectral(2, 3, Some(8));
    let config_path = dir.path().join("tiny.json");
    config.save(&config_path).expect("config");
    let exe = env!("CARGO_BIN_EXE_experiments");
    let fresh = |out: &Path| {
        Command::new(exe)
            .args([
                "train",
                "--config",
                &s(&config_path),
                "--data",
                &s(&data),
                "--out",
                &s(out),
                "-q",
            ])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("spawn train")
    };
    let resume = |out: &Path| {
        Command::new(exe)
            .args(["train", "--resume", &s(out), "--data", &s(&data), "-q"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("spawn train --resume")
    };
    let start = |out: &Path| {
        if deepbrdf_model::train::checkpoint_path(out).is_file() {
            resume(out)
        } else {
            fresh(out)
        }
    };

    let reference = dir.path().join("reference");
    let t = Instant::now();
    let o = fresh(&reference).wait_with_output().expect("reference run");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let full = t.elapsed();
    let expected = run_outputs(&reference);
    assert!(expected.iter().all(|(_, b)| !b.is_empty()), "the reference run left its files");

    let trials: usize =
        std::env::var(KILL_TRIALS_VAR).ok().and_then(|v| v.parse().ok()).unwrap_or(2);
    let mut kills = 0;
    for trial in 0..trials {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(trial as u64);
        let out = dir.path().join(format!("killed-{trial}"));
        // Up to three kills per trial at random moments over the run's length, then a run to the
        // end (a fresh start if no checkpoint was written yet, else --resume).
        for attempt in 0..rng.random_range(1..=3) {
            let mut child = start(&out);
            // The first attempt of a trial is killed a few milliseconds after its first
            // checkpoint appears (so every trial kills a run in the middle, however fast or
            // loaded the machine is); later ones at a random moment over the run's length.
            let after_checkpoint = attempt == 0;
            let delay = full.mul_f64(rng.random_range(0.05..1.1));
            let extra = Duration::from_millis(rng.random_range(0..40));
            let checkpoint = deepbrdf_model::train::checkpoint_path(&out);
            let had_checkpoint = checkpoint.is_file();
            let t = Instant::now();
            let mut finished = false;
            let mut seen: Option<Instant> = None;
            loop {
                if child.try_wait().expect("try_wait").is_some() {
                    finished = true;
                    break;
                }
                if after_checkpoint {
                    if seen.is_none() && (had_checkpoint || checkpoint.is_file()) {
                        seen = Some(Instant::now());
                    }
                    if seen.is_some_and(|at| at.elapsed() >= extra) {
                        break;
                    }
                } else if t.elapsed() >= delay {
                    break;
                }
                std::thread::sleep(Duration::from_millis(1));
            }
            if !finished {
                child.kill().expect("SIGKILL");
                kills += 1;
            }
            let _ = child.wait();
        }
        let o = start(&out).wait_with_output().expect("final run");
        assert!(
            o.status.success() || run_outputs(&out) == expected,
            "trial {trial}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let got = run_outputs(&out);
        for ((name, want), (_, have)) in expected.iter().zip(&got) {
            assert!(want == have, "trial {trial}: {name} differs from the uninterrupted run's");
        }
        // The model loads: a table encodes through it.
        let o = util::run_in(dir.path(), &["encode", &s(&out), &s(&data.join("m1.binary"))]);
        assert!(o.status.success(), "trial {trial}: {}", util::stderr(&o));
        eprintln!("kill test: trial {trial} bit-identical ({kills} SIGKILLs so far)");
    }
    eprintln!(
        "kill test: {trials} trials, {kills} SIGKILLs, all bit-identical to the uninterrupted run"
    );
    assert!(kills > 0, "no run was actually killed");
}
