//! `experiments bench serve [--model DIR] [MATERIAL]`: the browser editor's latency over HTTP
//! (target: a 128-px preview from request to image in <= 300 ms on 2 cores, and the page
//! responsive while 20 slider moves arrive within a second). Starts `serve`'s server on a free
//! loopback port in this process and times, as the page would ask them: opening the material;
//! fast previews of new roughness values (each a new latent: regressor, decode, render);
//! refined previews; and a burst of 20 roughness moves 50 ms apart sent without waiting (the
//! worst case: the page itself keeps one in flight), with the page and `/api/info` fetched
//! during the burst.
use crate::args::data::CacheArg;
use crate::editing::EditorArg;
use crate::serve::launch::{runtime, start};
use anyhow::{bail, Context};
use deepbrdf_data::Progress;
use deepbrdf_eval::stats::finite_median;
use serde_json::{json, Value};
use std::net::{Ipv4Addr, SocketAddr};
use std::time::{Duration, Instant};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub editor: EditorArg,
    /// The material to edit (a bundled id).
    #[arg(default_value = "merl/red-plastic")]
    pub material: String,
    /// Timed fast previews.
    #[arg(long, default_value_t = 10)]
    pub reps: usize,
    #[command(flatten)]
    pub cache: CacheArg,
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

/// The HTTP side of the benchmark: a client of the server at `base`.
struct Client {
    agent: ureq::Agent,
    base: String,
}

impl Client {
    /// POSTs `body`; the status, the body and the seconds it took.
    fn post(&self, path: &str, body: &Value) -> anyhow::Result<(u16, String, f64)> {
        let t = Instant::now();
        let mut r = self
            .agent
            .post(format!("{}{path}", self.base))
            .header("Content-Type", "application/json")
            .send(body.to_string())
            .with_context(|| format!("POST {path}"))?;
        let status = r.status().as_u16();
        let bytes = r.body_mut().with_config().limit(64 << 20).read_to_vec()?;
        let text = String::from_utf8_lossy(&bytes).into_owned();
        Ok((status, text, t.elapsed().as_secs_f64()))
    }

    fn get(&self, path: &str) -> anyhow::Result<f64> {
        let t = Instant::now();
        let mut r = self.agent.get(format!("{}{path}", self.base)).call()?;
        r.body_mut().read_to_vec()?;
        Ok(t.elapsed().as_secs_f64())
    }

    /// A preview of `roughness`; its status, the server's seconds and the round trip.
    fn preview(
        &self,
        material: &str,
        roughness: f64,
        quality: &str,
    ) -> anyhow::Result<(u16, Value, f64)> {
        let body =
            json!({"edit": {"material": material, "roughness": roughness}, "quality": quality});
        let (status, text, seconds) = self.post("/api/preview", &body)?;
        let value = serde_json::from_str(&text).unwrap_or(Value::Null);
        if status != 200 && status != 409 {
            bail!("preview: HTTP {status}: {text}");
        }
        Ok((status, value, seconds))
    }
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let runtime = runtime()?;
    let t = Instant::now();
    let addr = SocketAddr::from((Ipv4Addr::LOCALHOST, 0));
    let (listener, editor) = start(&runtime, &args.editor, &args.cache, addr)?;
    let load = t.elapsed().as_secs_f64();
    let base = format!("http://{}", listener.local_addr()?);
    let model = editor.model.clone();
    runtime.spawn(async move { axum::serve(listener, crate::serve::router(editor)).await });
    let agent: ureq::Agent =
        ureq::Agent::config_builder().http_status_as_error(false).build().into();
    let client = Client { agent, base };

    let (status, text, open) = client.post("/api/open", &json!({"material": args.material}))?;
    if status != 200 {
        bail!("opening {}: HTTP {status}: {text}", args.material);
    }
    let opened: Value = serde_json::from_str(&text)?;
    opened["attributes"]["roughness"].as_f64().context("the material's roughness")?;
    let (_, _, original) = client.post("/api/original", &json!({"material": args.material}))?;
    // A new roughness value for every preview (a new latent to decode), 0.02 ... 0.18.
    let value = |i: usize| 0.02 * 1.01f64.powi(i as i32);
    let timed = Previews::time(&client, &args.material, args.reps.max(1), &value)?;
    let Burst { answered, superseded, last_sent, last_done, page_max } =
        burst(&client, &args.material, &value)?;

    println!(
        "{}, model {} (k = {}), {} rayon threads; server and model load {load:.2} s",
        args.material,
        model.model_id,
        model.k,
        rayon::current_num_threads()
    );
    println!("open the material (attribute fit, encode, table sampler): {open:.2} s; original render {original:.2} s");
    timed.print();
    println!(
        "burst of 20 moves in {last_sent:.2} s: {answered} answered, {superseded} superseded \
         (409); the last answered {:.3} s after it was sent; page and /api/info during the \
         burst: at most {page_max:.3} s",
        last_done - last_sent
    );
    Ok(())
}

/// The previews' times in seconds: fast ones over HTTP (`trip`) and as the editor reports them
/// (total, decode, render), and refined ones over HTTP.
struct Previews {
    trip: Vec<f64>,
    server: Vec<f64>,
    decode: Vec<f64>,
    render: Vec<f64>,
    refined: Vec<f64>,
}

impl Previews {
    /// One warm-up, then `reps` fast previews and 3 refined ones, each of a new roughness
    /// `value(i)` (a new latent to decode).
    fn time(
        client: &Client,
        material: &str,
        reps: usize,
        value: &dyn Fn(usize) -> f64,
    ) -> anyhow::Result<Self> {
        client.preview(material, value(0), "fast")?;
        let mut t =
            Self { trip: vec![], server: vec![], decode: vec![], render: vec![], refined: vec![] };
        for i in 1..=reps {
            let (_, p, seconds) = client.preview(material, value(i), "fast")?;
            t.trip.push(seconds);
            t.server.push(p["seconds"]["total"].as_f64().unwrap_or(f64::NAN));
            t.decode.push(p["seconds"]["decode"].as_f64().unwrap_or(f64::NAN));
            t.render.push(p["seconds"]["render"].as_f64().unwrap_or(f64::NAN));
        }
        for i in 0..3 {
            let (_, _, seconds) = client.preview(material, value(100 + i), "refined")?;
            t.refined.push(seconds);
        }
        Ok(t)
    }

    fn print(self) {
        println!(
            "fast preview (128 px, {} spp), request to image over HTTP: median {:.3} s, max {:.3} s \
             (target <= 0.300 s); in the editor: {:.3} s (decode {:.3} s, render {:.3} s), {} previews",
            crate::serve::editor::FAST.spp,
            finite_median(self.trip.clone()),
            max(&self.trip),
            finite_median(self.server),
            finite_median(self.decode),
            finite_median(self.render),
            self.trip.len()
        );
        println!(
            "refined preview (256 px, {} spp, own table sampler, re-estimated attributes): median {:.3} s",
            crate::serve::editor::REFINED.spp,
            finite_median(self.refined)
        );
    }
}

/// What the burst of moves measured: the previews answered and superseded, when the last was
/// sent and answered (seconds from the start), and the slowest page or /api/info request.
struct Burst {
    answered: usize,
    superseded: usize,
    last_sent: f64,
    last_done: f64,
    page_max: f64,
}

/// The burst: 20 moves 50 ms apart (roughness `value(200 + i)`), each sent at once from its own
/// thread, with the page and /api/info fetched during it.
fn burst(
    client: &Client,
    material: &str,
    value: &(dyn Fn(usize) -> f64 + Sync),
) -> anyhow::Result<Burst> {
    let burst_start = Instant::now();
    let results = std::thread::scope(|s| {
        let handles: Vec<_> = (0..20)
            .map(|i| {
                let client = &client;
                let material = material;
                s.spawn(move || {
                    std::thread::sleep(Duration::from_millis(50 * i as u64));
                    let sent = burst_start.elapsed().as_secs_f64();
                    client
                        .preview(material, value(200 + i), "fast")
                        .map(|(st, _, secs)| (st, sent, secs))
                })
            })
            .collect();
        let mut pages = vec![];
        for _ in 0..8 {
            std::thread::sleep(Duration::from_millis(120));
            pages.push(client.get("/").and_then(|a| Ok((a, client.get("/api/info")?))));
        }
        let results: Vec<_> = handles.into_iter().map(|h| h.join()).collect();
        (results, pages)
    });
    let (previews, pages) = results;
    let mut answered = 0;
    let mut superseded = 0;
    let mut last_done: f64 = 0.0;
    let mut last_sent: f64 = 0.0;
    for r in previews {
        let (status, sent, secs) = r.map_err(|_| anyhow::anyhow!("a burst thread panicked"))??;
        match status {
            200 => answered += 1,
            _ => superseded += 1,
        }
        last_done = last_done.max(sent + secs);
        last_sent = last_sent.max(sent);
    }
    let pages: Vec<(f64, f64)> = pages.into_iter().collect::<anyhow::Result<_>>()?;
    let page_max = pages.iter().map(|p| p.0.max(p.1)).fold(0.0, f64::max);
    Ok(Burst { answered, superseded, last_sent, last_done, page_max })
}
