//! `experiments serve` end to end with the shipped default model: the bad-input cases over
//! plain HTTP (each a 4xx with a message, the server still answering after them, nothing
//! written outside its cache), and the page in a real browser: headless Chromium driven
//! through chromedriver by `fantoccini` loads the page, a slider moves, the preview changes,
//! 20 quick moves settle on the last one, and the edited `.binary` downloaded by the browser
//! is a valid MERL table.
//!
//! The browser test needs Debian's `chromium` and `chromium-driver` (`.ci/run` installs them);
//! without them it fails saying so. `DEEPBRDF_SERVE_SCREENSHOT=FILE` also saves a screenshot
//! of the page there (the README's).
use crate::util;
use deepbrdf_data::merl::read_merl;
use serde_json::{json, Value};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `experiments serve` (killed when dropped).
struct Server {
    child: Child,
    base: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `serve` on a free loopback port in `dir` (its cache in `dir/cache`), waiting for the
/// address it prints.
fn start_server(dir: &Path) -> Server {
    let cache = dir.join("cache");
    let mut child = Command::new(env!("CARGO_BIN_EXE_experiments"))
        .args(["serve", "--port", "0", "--quiet", "--cache"])
        .arg(&cache)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("spawning experiments serve");
    let stdout = child.stdout.take().expect("stdout");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if let Some(rest) = line.strip_prefix("serving the editor at ") {
                let url = rest.split_whitespace().next().unwrap_or("").trim_end_matches('/');
                let _ = tx.send(url.to_string());
            }
        }
    });
    let base = rx.recv_timeout(Duration::from_secs(60)).expect("serve printed no address in 60 s");
    assert!(base.starts_with("http://127.0.0.1:"), "binds loopback by default: {base}");
    Server { child, base }
}

fn agent() -> ureq::Agent {
    ureq::Agent::config_builder().http_status_as_error(false).build().into()
}

/// POSTs `body` (JSON text); status and response body.
fn post(base: &str, path: &str, body: &str) -> (u16, Vec<u8>) {
    let mut r = agent()
        .post(format!("{base}{path}"))
        .header("Content-Type", "application/json")
        .send(body)
        .expect("POST");
    let status = r.status().as_u16();
    (status, r.body_mut().with_config().limit(64 << 20).read_to_vec().expect("body"))
}

fn get(base: &str, path: &str) -> (u16, Vec<u8>) {
    let mut r = agent().get(format!("{base}{path}")).call().expect("GET");
    let status = r.status().as_u16();
    (status, r.body_mut().with_config().limit(64 << 20).read_to_vec().expect("body"))
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// `%`-encodes a query value.
fn encode(s: &str) -> String {
    s.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect()
}

/// Sends the head of an upload of `length` bytes without its body; the status and body of the
/// answer.
fn announce_upload(base: &str, name: &str, length: usize) -> (u16, String) {
    use std::io::{Read, Write};
    let addr = base.trim_start_matches("http://");
    let mut stream = std::net::TcpStream::connect(addr).expect("connecting");
    stream.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    let head = format!(
        "POST /api/upload?name={name} HTTP/1.1\r\nHost: {addr}\r\nContent-Length: {length}\r\n\
         Connection: close\r\n\r\n"
    );
    stream.write_all(head.as_bytes()).unwrap();
    let mut answer = Vec::new();
    let _ = stream.read_to_end(&mut answer);
    let answer = text(&answer);
    let status = answer.split_whitespace().nth(1).and_then(|s| s.parse().ok()).unwrap_or(0);
    (status, answer)
}

#[test]
fn serve_refuses_bad_input_with_4xx_and_keeps_running() {
    let dir = tempfile::tempdir().unwrap();
    let server = start_server(dir.path());
    let base = server.base.as_str();
    let (status, page) = get(base, "/");
    assert_eq!(status, 200);
    let page = text(&page);
    assert!(page.contains("DeepBRDF material editor"), "{page}");
    assert!(!page.contains("src=\"http") && !page.contains("href=\"http"), "external resources");

    let preview = |edit: Value| json!({"edit": edit, "quality": "fast"}).to_string();
    let m = "merl/red-plastic";
    let cases: Vec<(&str, String, u16, &str)> = vec![
        ("/api/open", json!({"material": "merl/no-such"}).to_string(), 404, "unknown material"),
        ("/api/open", json!({"material": "../../etc/passwd"}).to_string(), 400, "never by a path"),
        ("/api/open", json!({"material": "/etc/passwd"}).to_string(), 400, "never by a path"),
        ("/api/open", json!({"material": "merl/../x"}).to_string(), 400, "never by a path"),
        ("/api/open", json!({"material": "upload/0000"}).to_string(), 404, "not open"),
        ("/api/open", "{not json".into(), 400, "malformed"),
        ("/api/preview", preview(json!({"material": m, "roughness": "rough"})), 400, "malformed"),
        ("/api/preview", preview(json!({"material": m, "roughness": 5.0})), 400, "outside"),
        (
            "/api/preview",
            preview(json!({"material": m, "diffuse": [2, 0, 0]})),
            400,
            "diffuse albedo R",
        ),
        (
            "/api/preview",
            preview(json!({"material": m, "blend": {"material": "merl/chrome", "t": 3}})),
            400,
            "blend weight",
        ),
        (
            "/api/preview",
            preview(json!({"material": m, "scene": {"shape": "teapot"}})),
            400,
            "unknown shape",
        ),
        (
            "/api/preview",
            json!({"edit": {"material": m}, "quality": "ultra"}).to_string(),
            400,
            "malformed",
        ),
    ];
    for (path, body, want, needle) in &cases {
        let (status, answer) = post(base, path, body);
        let answer = text(&answer);
        assert_eq!(status, *want, "{path} {body}: {answer}");
        assert!(answer.contains(needle), "{path} {body}: {answer:?} lacks {needle:?}");
    }
    let upload = |name: &str, bytes: Vec<u8>| {
        let mut r = agent()
            .post(format!("{base}/api/upload?name={}", encode(name)))
            .send(&bytes[..])
            .expect("upload");
        let status = r.status().as_u16();
        (status, r.body_mut().read_to_string().unwrap_or_default())
    };
    for (name, bytes, want, needle) in [
        ("../evil.binary", vec![0u8; 10], 400, "no path"),
        ("notes.txt", vec![0u8; 10], 400, ".binary or .bsdf"),
        ("short.binary", vec![0u8; 100], 400, "not a MERL .binary"),
        ("bad.bsdf", b"not a tensor file".to_vec(), 400, "bad.bsdf"),
    ] {
        let (status, answer) = upload(name, bytes);
        assert_eq!(status, want, "{name}: {answer}");
        assert!(answer.contains(needle), "{name}: {answer:?} lacks {needle:?}");
    }
    // An oversized upload is refused from its length, before its body is read (sending the
    // body could race with the server closing the connection after its answer).
    let (status, answer) = announce_upload(base, "huge.binary", 65 << 20);
    assert_eq!(status, 413, "{answer}");
    assert!(answer.contains("larger than 64 MiB"), "{answer}");
    // A valid upload opens and edits like a bundled material.
    let file = dir.path().join("upload-source.binary");
    deepbrdf_data::merl::write_merl(&util::material(1), &file).unwrap();
    let (status, answer) = upload("synthetic.binary", std::fs::read(&file).unwrap());
    std::fs::remove_file(&file).unwrap();
    assert_eq!(status, 200, "{answer}");
    let opened: Value = serde_json::from_str(&answer).unwrap();
    let id = opened["id"].as_str().unwrap().to_string();
    assert!(id.starts_with("upload/") && opened["name"] == "synthetic", "{opened}");
    // So does an RGL measurement, converted through the server's cache.
    let bsdf = deepbrdf_data::rgl::bundled::bytes("paper_white_rgb").unwrap().to_vec();
    let (status, answer) = upload("paper.bsdf", bsdf);
    assert_eq!(status, 200, "{answer}");
    let paper: Value = serde_json::from_str(&answer).unwrap();
    assert!(paper["id"].as_str().unwrap().starts_with("upload/") && paper["name"] == "paper");
    let edit = json!({"material": id, "roughness": 0.2});
    let (status, answer) = post(base, "/api/preview", &preview(edit.clone()));
    assert_eq!(status, 200, "{}", text(&answer));
    let p: Value = serde_json::from_slice(&answer).unwrap();
    assert!(p["image"].as_str().unwrap().starts_with("data:image/png;base64,"));
    assert_eq!(p["requested"]["roughness"], 0.2);

    // Latest wins: a refined preview (8 render passes) still running when a newer preview
    // arrives stops and is answered 409; the newer one is answered.
    let refined = json!({"edit": {"material": m, "roughness": 0.3}, "quality": "refined"});
    let (old, new) = std::thread::scope(|s| {
        let old = s.spawn(|| post(base, "/api/preview", &refined.to_string()));
        std::thread::sleep(Duration::from_millis(300));
        let new = post(base, "/api/preview", &preview(json!({"material": m, "roughness": 0.31})));
        (old.join().unwrap(), new)
    });
    assert_eq!(old.0, 409, "{}", text(&old.1));
    assert!(text(&old.1).contains("superseded"), "{}", text(&old.1));
    assert_eq!(new.0, 200, "{}", text(&new.1));

    // A blend starts from the blend of both materials' attributes (roughness in log space).
    let open = |id: &str| -> Value {
        let (status, answer) = post(base, "/api/open", &json!({"material": id}).to_string());
        assert_eq!(status, 200, "{}", text(&answer));
        serde_json::from_slice(&answer).unwrap()
    };
    let (a, b) = (open("merl/red-plastic"), open("merl/chrome"));
    let blend =
        json!({"material": "merl/red-plastic", "blend": {"material": "merl/chrome", "t": 0.5}});
    let (status, answer) = post(base, "/api/preview", &preview(blend));
    assert_eq!(status, 200, "{}", text(&answer));
    let blended: Value = serde_json::from_slice(&answer).unwrap();
    let r = |v: &Value| v["roughness"].as_f64().unwrap();
    let (ra, rb, rm) = (r(&a["attributes"]), r(&b["attributes"]), r(&blended["base"]));
    assert!((rm - (ra * rb).sqrt()).abs() < 1e-9 * rm, "{ra} {rb} {rm}");
    let d = |v: &Value| v["diffuse"][0].as_f64().unwrap();
    let (da, db, dm) = (d(&a["attributes"]), d(&b["attributes"]), d(&blended["base"]));
    assert!((dm - (da + db) / 2.0).abs() < 1e-9, "{da} {db} {dm}");

    let download = |format: &str, edit: &Value| {
        get(base, &format!("/api/download?format={format}&edit={}", encode(&edit.to_string())))
    };
    let (status, answer) = download("exe", &edit);
    assert_eq!((status, text(&answer).contains("expected binary, bsdf or latent")), (400, true));
    let (status, answer) =
        download("binary", &json!({"material": "merl/red-plastic", "roughness": -1}));
    assert_eq!(status, 400, "{}", text(&answer));
    let (status, binary) = download("binary", &edit);
    assert_eq!(status, 200, "{}", text(&binary));
    let table = deepbrdf_data::merl::MerlFile::from_bytes(&binary, Path::new("download"))
        .and_then(|f| f.to_table())
        .expect("the download is a MERL table");
    assert!(table.valid_cells() > 1_000_000);
    let (status, bsdf) = download("bsdf", &edit);
    assert_eq!(status, 200, "{}", text(&bsdf));
    let brdf = deepbrdf_data::rgl::RglBrdf::parse(Path::new("download.bsdf"), &bsdf)
        .expect("the .bsdf download is an RGL file the project's reader reads");
    assert!(brdf.description().ends_with("(edited)"), "{}", brdf.description());
    let (status, latent) = download("latent", &edit);
    assert_eq!(status, 200);
    let latent: Value = serde_json::from_slice(&latent).unwrap();
    assert_eq!(latent["k"].as_u64().unwrap() as usize, latent["latent"].as_array().unwrap().len());
    let values = |v: &Value| -> Vec<f32> {
        v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect()
    };
    assert_eq!(
        values(&latent["latent"]),
        values(&p["latent"]),
        "the latent downloaded is the one previewed"
    );
    // The stretch edit edits the table: a preview without a latent, a table to download, no
    // latent file.
    let stretch = json!({"material": id, "roughness": 0.2, "mode": "stretch"});
    let (status, answer) = post(base, "/api/preview", &preview(stretch.clone()));
    assert_eq!(status, 200, "{}", text(&answer));
    let p: Value = serde_json::from_slice(&answer).unwrap();
    assert!(p["latent"].is_null() && p["requested"]["roughness"] == 0.2, "{p}");
    let (status, binary) = download("binary", &stretch);
    assert_eq!(status, 200, "{}", text(&binary));
    assert!(deepbrdf_data::merl::MerlFile::from_bytes(&binary, Path::new("stretch")).is_ok());
    let (status, answer) = download("latent", &stretch);
    assert_eq!(
        (status, text(&answer).contains("edits the table")),
        (400, true),
        "{}",
        text(&answer)
    );

    // Still answering; nothing written beside its cache.
    assert_eq!(get(base, "/api/info").0, 200);
    let written: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(written, ["cache"], "the server wrote beside its cache");
}

/// A program on the PATH (or the first given by `env`), if any.
fn program(env: &str, names: &[&str]) -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(env) {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|d| names.iter().map(move |n| d.join(n)))
        .find(|p| p.is_file())
}

/// A free loopback port (bound and released).
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// chromedriver, killed when dropped.
struct Driver(Child);

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

async fn wait_for(
    client: &fantoccini::Client,
    what: &str,
    script: &str,
    ok: impl Fn(&Value) -> bool,
) -> Value {
    let started = Instant::now();
    loop {
        let v = client.execute(script, vec![]).await.expect("script");
        if ok(&v) {
            return v;
        }
        let status = client
            .execute("return document.getElementById('status').textContent", vec![])
            .await
            .unwrap_or_default();
        assert!(
            started.elapsed() < Duration::from_secs(40),
            "waiting for {what}: {v} (page: {status})"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

#[test]
fn serve_page_edits_in_headless_chromium_and_downloads_a_merl_file() {
    let started = Instant::now();
    let install = "the browser test drives Chromium through chromedriver: install them with \
                   `sudo apt-get install -y chromium chromium-driver` (Debian; .ci/run does), or \
                   point CHROME and CHROMEDRIVER at them";
    let chrome = program("CHROME", &["chromium", "chromium-browser", "google-chrome"])
        .unwrap_or_else(|| panic!("no Chromium found: {install}"));
    let chromedriver = program("CHROMEDRIVER", &["chromedriver"])
        .unwrap_or_else(|| panic!("no chromedriver found: {install}"));
    let dir = tempfile::tempdir().unwrap();
    let work = dir.path().join("server");
    let downloads = dir.path().join("downloads");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::create_dir_all(&downloads).unwrap();
    let server = start_server(&work);
    let port = free_port();
    let driver = Driver(
        Command::new(&chromedriver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("starting {}: {e}: {install}", chromedriver.display())),
    );
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    runtime.block_on(async {
        let mut caps = serde_json::Map::new();
        caps.insert(
            "goog:chromeOptions".into(),
            json!({
                "binary": chrome,
                "args": ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                         "--window-size=1000,1010", "--hide-scrollbars"],
                "prefs": {"download.default_directory": downloads,
                          "download.prompt_for_download": false},
            }),
        );
        let connector = hyper_util::client::legacy::connect::HttpConnector::new();
        let url = format!("http://127.0.0.1:{port}");
        let t = Instant::now();
        let client = loop {
            let mut builder = fantoccini::ClientBuilder::new(connector.clone());
            match builder.capabilities(caps.clone()).connect(&url).await {
                Ok(c) => break c,
                Err(e) if t.elapsed() < Duration::from_secs(20) => {
                    let _ = e;
                    tokio::time::sleep(Duration::from_millis(200)).await
                }
                Err(e) => panic!("connecting to chromedriver at {url}: {e}: {install}"),
            }
        };
        client.goto(&format!("{}/?material=merl/red-plastic", server.base)).await.unwrap();
        let refined = "return +document.body.dataset.refined";
        let first = wait_for(&client, "the first refined preview", refined, |v| v.as_u64() > Some(0)).await;
        let edited = client.find(fantoccini::Locator::Id("edited")).await.unwrap();
        let before = edited.screenshot().await.unwrap();
        // Move the roughness slider to its end with the keyboard, as a user would.
        let slider = client.find(fantoccini::Locator::Id("roughness")).await.unwrap();
        slider.send_keys(&char::from(fantoccini::key::Key::End).to_string()).await.unwrap();
        let state = "return [+document.body.dataset.refined, \
                     document.getElementById('numbers').textContent]";
        let shows = |v: &Value, after: &Value, roughness: &str| {
            v[0].as_u64() > after.as_u64()
                && v[1].as_str().is_some_and(|t| {
                    let requested = format!("roughness {roughness}");
                    t.lines().any(|l| l.starts_with("requested") && l.ends_with(&requested))
                        && t.lines().any(|l| l.starts_with("achieved  diffuse"))
                })
        };
        let second = wait_for(&client, "the refined preview of the moved slider", state, |v| {
            shows(v, &first, "1.0000")
        })
        .await;
        let after = edited.screenshot().await.unwrap();
        assert_ne!(before, after, "the preview did not change when the slider moved");

        // 20 quick moves: the page settles on the last one.
        let slider = client.find(fantoccini::Locator::Id("roughness")).await.unwrap();
        let t = Instant::now();
        for _ in 0..20 {
            slider.send_keys(&char::from(fantoccini::key::Key::Left).to_string()).await.unwrap();
        }
        let moves = t.elapsed().as_secs_f64();
        let value = client
            .execute("return document.getElementById('roughness-v').textContent", vec![])
            .await
            .unwrap();
        let value = value.as_str().unwrap().to_string();
        assert_eq!(value, "0.6310", "20 steps of 0.01 down in log10 from 1");
        wait_for(&client, "the refined preview after 20 moves", state, |v| {
            shows(v, &second[0], &value)
        })
        .await;
        let settled = t.elapsed().as_secs_f64();
        eprintln!("20 slider moves in {moves:.2} s, settled after {settled:.2} s");

        if let Some(path) = std::env::var_os("DEEPBRDF_SERVE_SCREENSHOT") {
            std::fs::write(&path, client.screenshot().await.unwrap()).unwrap();
        }
        // Download the edited table through the browser.
        client.find(fantoccini::Locator::Id("download-binary")).await.unwrap().click().await.unwrap();
        let t = Instant::now();
        let file = loop {
            let done: Vec<PathBuf> = std::fs::read_dir(&downloads)
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|e| e == "binary"))
                .collect();
            if let [file] = &done[..] {
                if std::fs::metadata(file).unwrap().len() == 34_992_012 {
                    break file.clone();
                }
            }
            assert!(t.elapsed() < Duration::from_secs(30), "no download after 30 s: {done:?}");
            tokio::time::sleep(Duration::from_millis(100)).await;
        };
        assert_eq!(file.file_name().unwrap(), "red-plastic-edited.binary");
        let table = read_merl(&file).expect("the downloaded file is a valid MERL table");
        assert!(table.valid_cells() > 1_000_000);
        client.close().await.unwrap();
    });
    drop(driver);
    eprintln!("browser test: {:.1} s", started.elapsed().as_secs_f64());
}
