//! CLI tests of what happens around a run rather than inside it: a closed standard
//! output, two runs on one output folder, the lock of a killed run, a full disk and a read-only
//! folder, and the long jobs (`train`, `sweep-k`, `render-set`, `train-recovery`) killed at
//! random moments ([`kill`]).
//!
//! The disk tests mount a small tmpfs inside a private user and mount namespace
//! (`unshare --user --map-root-user --mount`), so they need no privileges and leave no mount
//! behind; `unshare` and `mount` come with util-linux.

use crate::{kill, util};
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

use crate::util::s;

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

/// The bytes a finished training run leaves that must not depend on how often it was killed.
fn run_outputs(run: &Path) -> Vec<(String, Vec<u8>)> {
    kill::files(run, &["model/weights.bpk", "train_log.csv"])
}

/// `cmd` with its output silenced but for stderr (read when a run fails).
fn spawn(mut cmd: Command) -> std::process::Child {
    cmd.stdout(std::process::Stdio::null()).stderr(std::process::Stdio::piped());
    cmd.spawn().expect("spawn experiments")
}

/// Three synthetic materials in `dir` and a training configuration for them: the slice
/// preset's network, tiny ([`util::tiny_train_config`]), trained `epochs` epochs with a checkpoint after every batch (so kills
/// land in epochs, in checkpoint writes and in the final save alike). Returns (data, config).
fn kill_test_setup(dir: &Path, epochs: usize) -> (std::path::PathBuf, std::path::PathBuf) {
    use deepbrdf_model::burn::config::Config as _;
    let data = util::write_data(dir, 3);
    let config = util::tiny_train_config()
        .with_epochs(epochs)
        .with_batch_size(1)
        .with_checkpoint_seconds(0.0);
    let config_path = dir.join("tiny.json");
    config.save(&config_path).expect("config");
    (data, config_path)
}

#[test]
fn train_killed_at_random_moments_resumes_to_bit_identical_weights() {
    use deepbrdf_model::train::checkpoint_path;

    let dir = tempfile::tempdir().expect("tempdir");
    let (data, config_path) = kill_test_setup(dir.path(), 60);
    let exe = env!("CARGO_BIN_EXE_experiments");
    // A fresh start if no checkpoint was written yet, else --resume.
    let start = |out: &Path| {
        let mut cmd = Command::new(exe);
        if checkpoint_path(out).is_file() {
            cmd.args(["train", "--resume", &s(out), "--data", &s(&data), "-q"]);
        } else {
            let config = s(&config_path);
            cmd.args(["train", "--config", &config, "--data", &s(&data), "--out", &s(out), "-q"]);
        }
        spawn(cmd)
    };
    let job = kill::Job {
        name: "train",
        start: &start,
        progress: &|out: &Path| checkpoint_path(out),
        outputs: &run_outputs,
    };
    // The model loads: a table encodes through it.
    let check = |out: &Path| {
        let o = util::run_in(dir.path(), &["encode", &s(out), &s(&data.join("m1.binary"))]);
        assert!(o.status.success(), "{}", util::stderr(&o));
    };
    kill::kill_trials(&job, dir.path(), kill::trials(2), &check);
}

#[test]
fn sweep_k_killed_at_random_moments_continues_to_identical_results() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (data, config_path) = kill_test_setup(dir.path(), 8);
    let exe = env!("CARGO_BIN_EXE_experiments");
    // The same command every time: sweep-k continues an interrupted run by itself.
    let start = |out: &Path| {
        let mut cmd = Command::new(exe);
        cmd.args(["sweep-k", "--data", &s(&data), "--ks", "1,2", "--train-config"])
            .args([s(&config_path), "--out".into(), s(out), "--fig2-material".into(), "m1".into()])
            .args(["--measures", "mapped_mse", "--fig2-ks", "2", "-q"])
            .args(["--mode", "in-sample", "--deep-ks", "all"]);
        spawn(cmd)
    };
    let outputs = |out: &Path| {
        kill::files(
            out,
            &[
                "results.csv",
                "robustness.csv",
                "models/fold0/k1/model/weights.bpk",
                "models/fold0/k2/model/weights.bpk",
            ],
        )
    };
    let job = kill::Job {
        name: "sweep-k",
        start: &start,
        progress: &|out: &Path| {
            deepbrdf_model::train::checkpoint_path(&out.join("models/fold0/k1"))
        },
        outputs: &outputs,
    };
    kill::kill_trials(&job, dir.path(), kill::trials(1), &|_| {});
}

/// A render set of `images` 32-px images of `data`'s materials in `out` (`-q`).
fn render_set_command(data: &Path, out: &Path, images: usize) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_experiments"));
    cmd.args(["render-set", "--out", &s(out), "--data", &s(data), "--images"]).args([
        images.to_string().as_str(),
        "--size",
        "32",
        "--spp",
        "8",
        "--seed",
        "3",
        "-q",
    ]);
    cmd
}

#[test]
fn render_set_killed_at_random_moments_finishes_to_identical_images() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (data, _) = kill_test_setup(dir.path(), 1);
    let images = 240;
    let names: Vec<String> = std::iter::once("manifest.json".to_string())
        .chain((0..images).map(|i| format!("img-{i:06}.png")))
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let outputs = |out: &Path| kill::files(out, &names);
    let job = kill::Job {
        name: "render-set",
        start: &|out: &Path| spawn(render_set_command(&data, out, images)),
        progress: &|out: &Path| out.join("img-000000.png"),
        outputs: &outputs,
    };
    // No temporary file of a killed write is left: the next run's lock removes them.
    let check = |out: &Path| {
        let stray: Vec<String> = std::fs::read_dir(out)
            .expect("set folder")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .filter(|n| !names.contains(&n.as_str()) && n != deepbrdf_data::lock::LOCK_FILE)
            .collect();
        assert!(stray.is_empty(), "files left by killed runs: {stray:?}");
    };
    kill::kill_trials(&job, dir.path(), kill::trials(2), &check);
}

#[test]
fn train_recovery_killed_at_random_moments_resumes_to_bit_identical_weights() {
    use deepbrdf_model::train::checkpoint_path;

    let dir = tempfile::tempdir().expect("tempdir");
    let (data, config_path) = kill_test_setup(dir.path(), 2);
    let model = dir.path().join("model");
    let o = util::run_in(
        dir.path(),
        &["train", "--config", &s(&config_path), "--data", &s(&data), "--out", &s(&model)],
    );
    assert!(o.status.success(), "{}", util::stderr(&o));
    let set = dir.path().join("set");
    let o = render_set_command(&data, &set, 12).output().expect("render-set");
    assert!(o.status.success(), "{}", util::stderr(&o));
    let exe = env!("CARGO_BIN_EXE_experiments");
    // A checkpoint after every epoch; --resume once one exists.
    let start = |out: &Path| {
        let mut cmd = Command::new(exe);
        cmd.args(["train-recovery", "--model", &s(&model), "--set", &s(&set), "--out", &s(out)])
            .args(["--epochs", "20", "--checkpoint-seconds", "0", "-q"]);
        if checkpoint_path(out).is_file() {
            cmd.arg("--resume");
        }
        spawn(cmd)
    };
    // recovery.json records the training time, so it is left out of the comparison.
    let outputs = |out: &Path| kill::files(out, &["recovery/weights.bpk", "train_log.csv"]);
    let job = kill::Job {
        name: "train-recovery",
        start: &start,
        progress: &|out: &Path| checkpoint_path(out),
        outputs: &outputs,
    };
    // The network recovers a material from a set image.
    let check = |out: &Path| {
        let net = s(&out.join("recovery"));
        let image = s(&set.join("img-000001.png"));
        let r = s(&out.join("r.binary"));
        let args = ["recover", "--model", &s(&model), "--network", &net, &image, "-o", &r];
        let o = util::run_in(dir.path(), &args);
        assert!(o.status.success(), "{}", util::stderr(&o));
    };
    kill::kill_trials(&job, dir.path(), kill::trials(2), &check);
}

#[test]
fn a_closed_standard_output_ends_the_command_without_a_panic() {
    // `experiments info m.binary | head -0`: the reader is gone before the first line.
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let data = util::write_data(dir.path(), 1);
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_experiments"))
        .args(["info", &util::s(&data.join("m0.binary")), "--quiet"])
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    let stderr = util::stderr(&out);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.signal(), Some(13), "ended by SIGPIPE: {:?} {stderr}", out.status);
}
