//! PyTorch's Table 1 beside Burn's in `experiments bench model`: the reference script
//! (`torch_table1.py`, the speed anchor in `../shared/bench`) run in the same command, with the
//! same threads and batch sizes, its seconds per training sample read from what it prints, and
//! the ratio Burn / PyTorch printed per row. Skipped, with a message saying why, where the
//! script or PyTorch is not there.
use std::path::PathBuf;
use std::process::Command;

#[derive(Debug, Clone, clap::Args)]
pub struct TorchArgs {
    /// The Python interpreter with PyTorch installed (`pip install torch`) that times PyTorch's
    /// Table 1 beside Burn's.
    #[arg(long, value_name = "PYTHON", default_value = "python3")]
    pub torch_python: PathBuf,
    /// PyTorch's Table 1 (the reference script).
    #[arg(long, value_name = "FILE", default_value = "../shared/bench/torch_table1.py")]
    pub torch_script: PathBuf,
    /// Do not time PyTorch.
    #[arg(long)]
    pub no_torch: bool,
}

/// Times PyTorch at the batch sizes of `rows` (name, batch, Burn's seconds per sample) and
/// prints each row beside it with the ratio.
pub fn compare(
    args: &TorchArgs,
    rows: &[(String, usize, f64)],
    steps: usize,
) -> anyhow::Result<()> {
    if args.no_torch || rows.is_empty() {
        return Ok(());
    }
    let mut batches: Vec<usize> = rows.iter().map(|r| r.1).collect();
    batches.sort_unstable();
    batches.dedup();
    let threads = rayon::current_num_threads();
    let torch = match torch_per_sample(args, &batches, threads, steps) {
        Ok(t) => t,
        Err(why) => {
            println!("PyTorch not timed: {why}");
            return Ok(());
        }
    };
    println!(
        "Table 1 training step per sample, Burn beside PyTorch ({threads} threads each, same run):"
    );
    println!(
        "{:24} {:>6} {:>12} {:>12} {:>14}",
        "network", "batch", "Burn s", "PyTorch s", "Burn/PyTorch"
    );
    for (name, batch, burn) in rows {
        match torch.iter().find(|(b, _)| b == batch) {
            Some((_, t)) => {
                println!("{name:24} {batch:>6} {burn:>12.4} {t:>12.4} {:>13.2}x", burn / t)
            }
            None => println!("{name:24} {batch:>6} {burn:>12.4} {:>12}", "-"),
        }
    }
    Ok(())
}

/// PyTorch's seconds per training sample at each batch size, or why it could not be timed.
fn torch_per_sample(
    args: &TorchArgs,
    batches: &[usize],
    threads: usize,
    steps: usize,
) -> Result<Vec<(usize, f64)>, String> {
    if !args.torch_script.is_file() {
        return Err(format!("{} not found (--torch-script)", args.torch_script.display()));
    }
    let list = batches.iter().map(|b| b.to_string()).collect::<Vec<_>>().join(",");
    let output = Command::new(&args.torch_python)
        .arg(&args.torch_script)
        .args(["--mode", "train", "--batch", &list, "--threads", &threads.to_string()])
        .args(["--steps", &steps.max(2).to_string()])
        .output()
        .map_err(|e| format!("cannot run {}: {e}", args.torch_python.display()))?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let last = stderr.lines().last().unwrap_or("no message");
        return Err(format!(
            "{} failed ({last}); is PyTorch installed there?",
            args.torch_python.display()
        ));
    }
    let parsed = parse_torch(&stdout);
    if parsed.len() != batches.len() {
        return Err(format!("unexpected output from {}: {stdout}", args.torch_script.display()));
    }
    Ok(parsed)
}

/// `(batch, seconds per sample)` of each `batch B: train step median X s, Y s per sample` line.
fn parse_torch(stdout: &str) -> Vec<(usize, f64)> {
    stdout
        .lines()
        .filter_map(|line| {
            let rest = line.strip_prefix("batch ")?;
            let (batch, rest) = rest.split_once(':')?;
            let per_sample = rest.split(',').nth(1)?.trim().strip_suffix(" s per sample")?;
            Some((batch.trim().parse().ok()?, per_sample.trim().parse().ok()?))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pytorch_lines_are_read() {
        let out = "torch 2.15.0 device cpu threads 2 params 4609766\n\
                   batch 4: train step median 1.485 s, 0.371 s per sample\n\
                   batch 32: train step median 14.3 s, 0.447 s per sample\nmax RSS MB 1312\n";
        assert_eq!(parse_torch(out), vec![(4, 0.371), (32, 0.447)]);
        assert!(parse_torch("batch x: nothing").is_empty());
    }

    #[test]
    fn a_missing_script_is_said_not_fatal() {
        let args = TorchArgs {
            torch_python: "python3".into(),
            torch_script: "/nonexistent/torch_table1.py".into(),
            no_torch: false,
        };
        let why = torch_per_sample(&args, &[4], 2, 2).unwrap_err();
        assert!(why.contains("not found"), "{why}");
        compare(&args, &[("paper".into(), 4, 0.5)], 2).unwrap();
    }
}
