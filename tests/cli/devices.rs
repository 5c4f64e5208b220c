//! `experiments devices` and `--device`: the listing says, for every backend, exactly what the
//! library compiled into this build says, and `--device` accepts those and only those.
use crate::util;
use deepbrdf_model::DeviceKind;

#[test]
fn devices_lists_every_backend_with_its_real_state() {
    let out = util::run(&["devices"]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    let lines: Vec<(&str, String)> = text
        .lines()
        .map(|l| {
            let (name, state) = l.split_once(' ').unwrap_or((l, ""));
            (name, state.trim().to_string())
        })
        .collect();
    assert_eq!(lines.len(), DeviceKind::ALL.len(), "{text}");
    for (kind, (name, state)) in DeviceKind::ALL.iter().zip(&lines) {
        assert_eq!(*name, kind.name(), "{text}");
        let want = if kind.is_compiled() { "available" } else { "not compiled in" };
        assert_eq!(state, want, "{text}");
    }
    assert!(DeviceKind::Flex.is_compiled(), "flex is the default backend");
}

#[test]
fn device_option_rejects_unknown_and_missing_backends_by_name() {
    let unknown = util::run(&["baselines", "--device", "tpu", "--data", "no-such-dir"]);
    util::assert_clean_failure(&unknown, "unknown device 'tpu'");
    for kind in DeviceKind::ALL.iter().filter(|k| !k.is_compiled()) {
        let out = util::run(&["baselines", "--device", kind.name(), "--data", "no-such-dir"]);
        util::assert_clean_failure(&out, &format!("'{}' is not compiled", kind.name()));
    }
    // An available backend passes the option and the run fails on the data instead.
    let ok = util::run(&["baselines", "--device", "flex", "--data", "no-such-dir"]);
    util::assert_clean_failure(&ok, "no-such-dir");
}
