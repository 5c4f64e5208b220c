//! `experiments fetch-merl` against a tiny HTTP/1.1 server on 127.0.0.1 started by each test:
//! small files with a checksum table of the test's own; no internet.
use crate::util;
use sha2::{Digest, Sha256};
use std::collections::{HashMap, HashSet};
use std::io::{BufRead, BufReader, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// One request the server saw: the path and the `Range` header, if any.
#[derive(Debug, Clone)]
struct Seen {
    path: String,
    range: Option<String>,
}

#[derive(Default)]
struct ServerState {
    files: HashMap<String, Vec<u8>>,
    /// Paths whose first request is answered with half the body, then the connection drops.
    drop_once: HashSet<String>,
    /// Answer every request with the whole file (200), as servers without range support do.
    ignore_range: bool,
    log: Vec<Seen>,
}

/// A one-thread-per-connection HTTP/1.1 file server for `GET /brdfs/NAME.binary`.
struct Server {
    port: u16,
    state: Arc<Mutex<ServerState>>,
}

impl Server {
    fn start(files: &[(&str, Vec<u8>)]) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").expect("bind 127.0.0.1:0");
        let port = listener.local_addr().expect("local addr").port();
        let mut state = ServerState::default();
        for (name, bytes) in files {
            state.files.insert(format!("/brdfs/{name}.binary"), bytes.clone());
        }
        let state = Arc::new(Mutex::new(state));
        let shared = Arc::clone(&state);
        // The thread lives until the test binary exits.
        std::thread::spawn(move || {
            for stream in listener.incoming().flatten() {
                let shared = Arc::clone(&shared);
                std::thread::spawn(move || serve(stream, &shared));
            }
        });
        Self { port, state }
    }

    fn base_url(&self) -> String {
        format!("http://127.0.0.1:{}/brdfs/", self.port)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, ServerState> {
        self.state.lock().expect("server state")
    }

    fn log(&self) -> Vec<Seen> {
        self.lock().log.clone()
    }
}

fn serve(mut stream: TcpStream, state: &Mutex<ServerState>) {
    let Ok(clone) = stream.try_clone() else { return };
    let mut reader = BufReader::new(clone);
    let mut request_line = String::new();
    if reader.read_line(&mut request_line).is_err() {
        return;
    }
    let mut range = None;
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line).is_err() || line == "\r\n" || line.is_empty() {
            break;
        }
        if let Some((name, value)) = line.split_once(':') {
            if name.trim().eq_ignore_ascii_case("range") {
                range = Some(value.trim().to_string());
            }
        }
    }
    let path = request_line.split_whitespace().nth(1).unwrap_or("").to_string();
    let (body, start, drop_half, ignore_range) = {
        let mut st = state.lock().expect("server state");
        st.log.push(Seen { path: path.clone(), range: range.clone() });
        let body = st.files.get(&path).cloned();
        let drop_half = st.drop_once.remove(&path);
        let start = range
            .as_deref()
            .and_then(|r| r.strip_prefix("bytes="))
            .and_then(|r| r.strip_suffix('-'))
            .and_then(|n| n.parse::<usize>().ok());
        (body, start, drop_half, st.ignore_range)
    };
    let Some(body) = body else {
        let _ = stream.write_all(
            b"HTTP/1.1 404 Not Found\r\nContent-Length: 9\r\nConnection: close\r\n\r\nnot found",
        );
        return;
    };
    let (head, payload) = match start {
        Some(s) if !ignore_range && s < body.len() => (
            format!(
                "HTTP/1.1 206 Partial Content\r\nContent-Range: bytes {s}-{}/{}\r\nContent-Length: {}\r\n",
                body.len() - 1,
                body.len(),
                body.len() - s
            ),
            &body[s..],
        ),
        Some(s) if !ignore_range && s >= body.len() => {
            let head = format!("HTTP/1.1 416 Range Not Satisfiable\r\nContent-Range: bytes */{}\r\n", body.len());
            let _ = stream.write_all(format!("{head}Content-Length: 0\r\nConnection: close\r\n\r\n").as_bytes());
            return;
        }
        _ => (format!("HTTP/1.1 200 OK\r\nContent-Length: {}\r\n", body.len()), &body[..]),
    };
    let _ = stream.write_all(format!("{head}Connection: close\r\n\r\n").as_bytes());
    if drop_half {
        let _ = stream.write_all(&payload[..payload.len() / 2]);
        let _ = stream.flush();
        let _ = stream.shutdown(Shutdown::Both);
        return;
    }
    let _ = stream.write_all(payload);
    let _ = stream.flush();
}

/// Deterministic bytes (a 64-bit LCG), different for each seed.
fn content(seed: u64, len: usize) -> Vec<u8> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..len)
        .map(|_| {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (x >> 56) as u8
        })
        .collect()
}

fn sha256_hex(bytes: &[u8]) -> String {
    hex::encode(Sha256::digest(bytes))
}

/// Writes a checksum table for `(name, bytes)` pairs and returns its path.
fn write_table(dir: &Path, files: &[(&str, &[u8])]) -> PathBuf {
    let mut text = String::from("material\tsha256\tsize\n");
    for (name, bytes) in files {
        text.push_str(&format!("{name}\t{}\t{}\n", sha256_hex(bytes), bytes.len()));
    }
    let path = dir.join("sums.tsv");
    std::fs::write(&path, text).expect("write table");
    path
}

/// Runs `fetch-merl` into `dir/out` against `server` with `table`, no retry wait.
fn fetch(dir: &Path, server: &Server, table: &Path, extra: &[&str]) -> std::process::Output {
    let base = server.base_url();
    let table = table.to_str().expect("utf-8 path");
    let mut args = vec![
        "fetch-merl",
        "--out",
        "out",
        "--base-url",
        &base,
        "--checksums",
        table,
        "--retry-wait",
        "0",
    ];
    args.extend_from_slice(extra);
    util::run_in(dir, &args)
}

/// Files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("read out dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn three_files() -> Vec<(&'static str, Vec<u8>)> {
    vec![
        ("alpha", content(1, 3_000)),
        ("beta-2", content(2, 150_001)),
        ("gamma", content(3, 70_000)),
    ]
}

#[test]
fn fetch_merl_downloads_verifies_and_then_skips_good_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let files = three_files();
    let server = Server::start(&files);
    let refs: Vec<(&str, &[u8])> = files.iter().map(|(n, b)| (*n, b.as_slice())).collect();
    let table = write_table(dir.path(), &refs);

    let out = fetch(dir.path(), &server, &table, &[]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert!(
        util::stdout(&out).contains("3 downloaded, 0 already present"),
        "{}",
        util::stdout(&out)
    );
    for (name, bytes) in &files {
        let got = std::fs::read(dir.path().join("out").join(format!("{name}.binary")))
            .expect("downloaded file");
        assert_eq!(&got, bytes, "{name} differs");
    }
    assert_eq!(listing(&dir.path().join("out")), ["alpha.binary", "beta-2.binary", "gamma.binary"]);
    assert!(server.log().iter().all(|s| s.range.is_none()), "{:?}", server.log());

    // A second run finds every file verified and asks the server for nothing.
    let requests = server.log().len();
    let again = fetch(dir.path(), &server, &table, &[]);
    assert!(again.status.success(), "{}", util::stderr(&again));
    assert!(
        util::stdout(&again).contains("0 downloaded, 3 already present and verified"),
        "{}",
        util::stdout(&again)
    );
    assert_eq!(server.log().len(), requests, "a verified file was downloaded again");
}

#[test]
fn fetch_merl_resumes_an_interrupted_download_with_a_range_request() {
    let dir = tempfile::tempdir().expect("tempdir");
    let files = three_files();
    let server = Server::start(&files);
    server.lock().drop_once.insert("/brdfs/beta-2.binary".into());
    let refs: Vec<(&str, &[u8])> = files.iter().map(|(n, b)| (*n, b.as_slice())).collect();
    let table = write_table(dir.path(), &refs);
    // A part file left by an earlier, interrupted run.
    std::fs::create_dir(dir.path().join("out")).expect("mkdir out");
    std::fs::write(dir.path().join("out/gamma.binary.part"), &files[2].1[..1_000])
        .expect("write part");

    let out = fetch(dir.path(), &server, &table, &["--materials", "beta-2,gamma"]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    let log = server.log();
    let beta: Vec<&Seen> = log.iter().filter(|s| s.path == "/brdfs/beta-2.binary").collect();
    assert_eq!(beta.len(), 2, "one dropped and one resumed request: {log:?}");
    assert_eq!(beta[0].range, None);
    assert_eq!(
        beta[1].range.as_deref(),
        Some(format!("bytes={}-", 150_001 / 2).as_str()),
        "{log:?}"
    );
    let gamma: Vec<&Seen> = log.iter().filter(|s| s.path == "/brdfs/gamma.binary").collect();
    assert_eq!(gamma.len(), 1, "{log:?}");
    assert_eq!(gamma[0].range.as_deref(), Some("bytes=1000-"));
    assert!(!log.iter().any(|s| s.path == "/brdfs/alpha.binary"), "--materials ignored: {log:?}");
    for (name, bytes) in &files[1..] {
        let got = std::fs::read(dir.path().join("out").join(format!("{name}.binary")))
            .expect("downloaded file");
        assert_eq!(&got, bytes, "{name} differs after resuming");
    }
    assert_eq!(listing(&dir.path().join("out")), ["beta-2.binary", "gamma.binary"]);
}

#[test]
fn fetch_merl_starts_over_when_the_server_ignores_range() {
    let dir = tempfile::tempdir().expect("tempdir");
    let files = vec![("alpha", content(7, 20_000))];
    let server = Server::start(&files);
    server.lock().ignore_range = true;
    let table = write_table(dir.path(), &[("alpha", &files[0].1)]);
    std::fs::create_dir(dir.path().join("out")).expect("mkdir out");
    // A stale part whose bytes do not match the file: only a restart from 0 gives the right file.
    std::fs::write(dir.path().join("out/alpha.binary.part"), vec![0xAB; 5_000])
        .expect("write part");

    let out = fetch(dir.path(), &server, &table, &[]);
    assert!(out.status.success(), "{}", util::stderr(&out));
    assert_eq!(server.log()[0].range.as_deref(), Some("bytes=5000-"));
    let got = std::fs::read(dir.path().join("out/alpha.binary")).expect("downloaded");
    assert_eq!(got, files[0].1);
    assert_eq!(listing(&dir.path().join("out")), ["alpha.binary"]);
}

#[test]
fn fetch_merl_rejects_wrong_content_and_leaves_no_file_under_the_final_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let files = vec![("alpha", content(1, 4_000)), ("bad-one", content(2, 9_000))];
    let server = Server::start(&files);
    // The table expects other bytes of the same size for bad-one.
    let expected_bad = content(99, 9_000);
    let table = write_table(dir.path(), &[("alpha", &files[0].1), ("bad-one", &expected_bad)]);

    let out = fetch(dir.path(), &server, &table, &[]);
    util::assert_clean_failure(&out, "bad-one: checksum mismatch");
    let err = util::stderr(&out);
    assert!(
        err.contains(&sha256_hex(&expected_bad)) && err.contains(&sha256_hex(&files[1].1)),
        "{err}"
    );
    assert!(err.contains("1 of 2 materials could not be fetched"), "{err}");
    // The good file still arrived; the bad one left neither a final file nor a part file.
    assert_eq!(listing(&dir.path().join("out")), ["alpha.binary"]);
}

#[test]
fn fetch_merl_keeps_a_wrong_existing_file_unless_forced() {
    let dir = tempfile::tempdir().expect("tempdir");
    let files = vec![("alpha", content(1, 4_000))];
    let server = Server::start(&files);
    let table = write_table(dir.path(), &[("alpha", &files[0].1)]);
    std::fs::create_dir(dir.path().join("out")).expect("mkdir out");
    let user_data = content(5, 4_000);
    std::fs::write(dir.path().join("out/alpha.binary"), &user_data).expect("write existing");

    let out = fetch(dir.path(), &server, &table, &[]);
    util::assert_clean_failure(&out, "alpha.binary already exists but its SHA-256 is");
    assert!(util::stderr(&out).contains("--force"), "{}", util::stderr(&out));
    assert_eq!(
        std::fs::read(dir.path().join("out/alpha.binary")).expect("read"),
        user_data,
        "user file changed"
    );
    assert!(server.log().is_empty(), "downloaded despite the conflict");

    let forced = fetch(dir.path(), &server, &table, &["--force"]);
    assert!(forced.status.success(), "{}", util::stderr(&forced));
    assert!(util::stdout(&forced).contains("alpha.binary.mismatch"), "{}", util::stdout(&forced));
    assert_eq!(std::fs::read(dir.path().join("out/alpha.binary")).expect("read"), files[0].1);
    assert_eq!(
        std::fs::read(dir.path().join("out/alpha.binary.mismatch")).expect("read"),
        user_data
    );
}

#[test]
fn fetch_merl_reports_http_404_with_the_url() {
    let dir = tempfile::tempdir().expect("tempdir");
    let server = Server::start(&[]);
    let table = write_table(dir.path(), &[("missing", &content(1, 100))]);

    let out = fetch(dir.path(), &server, &table, &[]);
    let url = format!("{}missing.binary", server.base_url());
    util::assert_clean_failure(&out, &format!("missing: GET {url}: HTTP 404 (Not Found)"));
    assert_eq!(server.log().len(), 1, "a 404 must not be retried");
    assert!(listing(&dir.path().join("out")).is_empty());
}

#[test]
fn fetch_merl_reports_an_unreachable_server_and_stops() {
    let dir = tempfile::tempdir().expect("tempdir");
    // A port with no listener: bind, read the port, close.
    let port = TcpListener::bind("127.0.0.1:0").expect("bind").local_addr().expect("addr").port();
    let table = write_table(dir.path(), &[("a", &content(1, 10)), ("b", &content(2, 10))]);
    let base = format!("http://127.0.0.1:{port}/brdfs");
    let out = util::run_in(
        dir.path(),
        &[
            "fetch-merl",
            "--out",
            "out",
            "--base-url",
            &base,
            "--checksums",
            table.to_str().expect("utf-8"),
            "--retries",
            "1",
            "--retry-wait",
            "0",
        ],
    );
    util::assert_clean_failure(&out, &format!("a: GET {base}/a.binary: "));
    let err = util::stderr(&out);
    assert!(err.contains("gave up after 2 attempts"), "{err}");
    assert!(err.contains("not attempted after the connection failure: b"), "{err}");
}

#[test]
fn fetch_merl_rejects_bad_tables_and_unknown_materials() {
    let dir = tempfile::tempdir().expect("tempdir");
    let server = Server::start(&[]);
    let bad = dir.path().join("bad.tsv");
    std::fs::write(&bad, "material\tsha256\tsize\nalpha\tnot-a-digest\t10\n").expect("write");
    let out = fetch(dir.path(), &server, &bad, &[]);
    util::assert_clean_failure(&out, "bad.tsv: line 2: material alpha: sha256");

    let table = write_table(dir.path(), &[("alpha", &content(1, 10))]);
    let out = fetch(dir.path(), &server, &table, &["--materials", "alpha,nope"]);
    util::assert_clean_failure(&out, "\"nope\" is not in the checksum table");
    assert!(server.log().is_empty());
}
