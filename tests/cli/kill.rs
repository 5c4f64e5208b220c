//! The kill harness of the reliability tests: a long job is SIGKILLed at random
//! moments and restarted until it finishes, trial after trial, and what each trial leaves must be
//! byte-identical to what an uninterrupted run left.
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};
use std::process::Child;
use std::time::{Duration, Instant};

/// Environment variable that sets the trials per job (the README's reliability table was
/// measured with 20); CI runs the defaults of each test.
pub const KILL_TRIALS_VAR: &str = "DEEPBRDF_KILL_TRIALS";

/// Trials for this run: [`KILL_TRIALS_VAR`] if set, else `default`.
pub fn trials(default: usize) -> usize {
    std::env::var(KILL_TRIALS_VAR).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// A job that can be killed and continued.
pub struct Job<'a> {
    /// Its name in messages.
    pub name: &'a str,
    /// Starts the job in output folder `out`, or continues it there.
    pub start: &'a dyn Fn(&Path) -> Child,
    /// The file whose appearance in `out` shows that the job has saved progress (a checkpoint).
    pub progress: &'a dyn Fn(&Path) -> PathBuf,
    /// The files a finished job leaves in `out` that must not depend on how often it was
    /// killed, with their bytes.
    pub outputs: &'a dyn Fn(&Path) -> Vec<(String, Vec<u8>)>,
}

/// Runs `job` once uninterrupted in `root/reference`, then `trials` times in `root/killed-N`
/// with one to three SIGKILLs per trial (the first run of a trial a few milliseconds after its
/// first checkpoint appears, so every trial kills a run in the middle however fast or loaded the
/// machine is; later ones at a random moment over the run's length), each trial run to the end
/// and compared with the reference; `check` then looks at each finished trial's folder. Returns
/// the number of kills.
pub fn kill_trials(job: &Job<'_>, root: &Path, trials: usize, check: &dyn Fn(&Path)) -> usize {
    let reference = root.join("reference");
    let t = Instant::now();
    let o = (job.start)(&reference).wait_with_output().expect("reference run");
    assert!(o.status.success(), "{}: {}", job.name, String::from_utf8_lossy(&o.stderr));
    let full = t.elapsed();
    let expected = (job.outputs)(&reference);
    assert!(expected.iter().all(|(_, b)| !b.is_empty()), "the reference run left its files");

    let mut kills = 0;
    for trial in 0..trials {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(trial as u64);
        let out = root.join(format!("killed-{trial}"));
        for attempt in 0..rng.random_range(1..=3) {
            let mut child = (job.start)(&out);
            let after_checkpoint = attempt == 0;
            let delay = full.mul_f64(rng.random_range(0.05..1.1));
            let extra = Duration::from_millis(rng.random_range(0..40));
            let progress = (job.progress)(&out);
            let had_progress = progress.is_file();
            let t = Instant::now();
            let mut finished = false;
            let mut seen: Option<Instant> = None;
            loop {
                if child.try_wait().expect("try_wait").is_some() {
                    finished = true;
                    break;
                }
                if after_checkpoint {
                    if seen.is_none() && (had_progress || progress.is_file()) {
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
        let o = (job.start)(&out).wait_with_output().expect("final run");
        assert!(
            o.status.success() || (job.outputs)(&out) == expected,
            "{} trial {trial}: {}",
            job.name,
            String::from_utf8_lossy(&o.stderr)
        );
        let got = (job.outputs)(&out);
        for ((name, want), (_, have)) in expected.iter().zip(&got) {
            assert!(
                want == have,
                "{} trial {trial}: {name} differs from the uninterrupted run's",
                job.name
            );
        }
        check(&out);
        eprintln!("kill test {}: trial {trial} bit-identical ({kills} SIGKILLs so far)", job.name);
    }
    eprintln!(
        "kill test {}: {trials} trials, {kills} SIGKILLs, all bit-identical to the uninterrupted run",
        job.name
    );
    assert!(kills > 0, "{}: no run was actually killed", job.name);
    kills
}

/// The named files under `out`, with their bytes (empty if missing).
pub fn files(out: &Path, names: &[&str]) -> Vec<(String, Vec<u8>)> {
    names.iter().map(|f| (f.to_string(), std::fs::read(out.join(f)).unwrap_or_default())).collect()
}
