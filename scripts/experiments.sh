# Sourced by the scripts in this folder: `run ARGS...` runs the `experiments` command line, the
# binary in $EXPERIMENTS when set (e.g. target/release/experiments), else through `cargo run`.
if [[ -n "${EXPERIMENTS:-}" ]]; then
    run() { "$EXPERIMENTS" "$@"; }
else
    run() { cargo run --release -q -p experiments -- "$@"; }
fi
