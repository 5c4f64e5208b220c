use crate::util;

#[test]
fn devices_lists_flex_as_available() {
    let out = util::run(&["devices"]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let text = util::stdout(&out);
    assert!(text.lines().any(|l| l.starts_with("flex") && l.ends_with("available")), "{text}");
}
