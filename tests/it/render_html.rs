//! The HTML viewer in a real browser: headless Chromium opens generated pages with `#selftest`,
//! the page draws two frames and writes what it saw (drawn pixels, pixels that differ, script
//! errors) as JSON into `<pre id="selftest">`, and `--dump-dom` hands that back to us.
//!
//! Skipped (with a printed SKIP line) when no Chromium is installed; CI installs Debian's `chromium`.

use crate::common;

use menagerie::bvh;
use menagerie::motion::Motion;
use menagerie::render::html::{decoded_positions, render_html, HtmlOptions};
use menagerie::render::{Legend, Track};
use menagerie::skeleton::Skeleton;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn example_track(name: &str) -> Track {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data").join(format!("{name}.bvh"));
    bvh_track(&path)
}

fn bvh_track(path: &Path) -> Track {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("read {}: {e}", path.display()));
    let name = path.file_name().unwrap().to_string_lossy().to_string();
    let parsed = bvh::parse_bytes(&bytes, &name).unwrap();
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    Track::from_motion(&name, &skeleton, &motion)
}

fn find_chromium() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"]
        .iter()
        .flat_map(|name| std::env::split_paths(&path).map(move |dir| dir.join(name)))
        .find(|p| p.is_file())
}

/// A scratch directory of this test run (pages and browser profiles), removed when dropped,
/// also when the test fails, unless `MENAGERIE_KEEP_HTML` is set (to look at the pages).
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Scratch {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("render_html_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::env::var_os("MENAGERIE_KEEP_HTML").is_some() {
            eprintln!("pages kept in {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A running headless browser with a deadline; its DOM dump is read on a thread so a full
/// pipe never blocks it.
struct Browser {
    child: std::process::Child,
    stdout: Option<std::thread::JoinHandle<String>>,
    stderr: Option<std::thread::JoinHandle<String>>,
}

fn open(chromium: &Path, page: &Path, profile: &Path) -> Browser {
    let url = format!("file://{}#selftest", page.display());
    let mut child = Command::new(chromium)
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-extensions", "--mute-audio"])
        // Containers often have a tiny /dev/shm, which crashes Chromium's renderer.
        .arg("--disable-dev-shm-usage")
        // Nothing on the page needs the network; keep the browser from reaching for it too.
        .args(["--disable-background-networking", "--disable-component-update", "--disable-sync", "--disable-default-apps"])
        .arg("--window-size=800,600")
        .arg("--virtual-time-budget=5000")
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg("--dump-dom")
        .arg(url)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start chromium");
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let stdout = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let stderr = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    Browser { child, stdout: Some(stdout), stderr: Some(stderr) }
}

/// A browser left running by a failing test is killed, never leaked.
impl Drop for Browser {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// Wait for the browser (killing it after `limit`) and return the self test's JSON.
fn finish(mut b: Browser, limit: Duration, what: &str) -> serde_json::Value {
    let start = Instant::now();
    loop {
        match b.child.try_wait().expect("poll chromium") {
            Some(_) => break,
            None if start.elapsed() > limit => {
                drop(b);
                panic!("{what}: chromium did not finish within {limit:?}");
            }
            None => std::thread::sleep(Duration::from_millis(20)),
        }
    }
    let dom = b.stdout.take().map(|h| h.join().unwrap()).unwrap_or_default();
    let stderr = b.stderr.take().map(|h| h.join().unwrap()).unwrap_or_default();
    let tail: String = stderr.lines().rev().take(15).collect::<Vec<_>>().into_iter().rev().collect::<Vec<_>>().join("\n");
    let start = dom.find("id=\"selftest\"").and_then(|i| dom[i..].find('>').map(|j| i + j + 1));
    let text = start.and_then(|s| dom[s..].find("</pre>").map(|e| &dom[s..s + e])).unwrap_or("");
    // --dump-dom writes element text HTML-escaped.
    let text = text.replace("&lt;", "<").replace("&gt;", ">").replace("&quot;", "\"").replace("&amp;", "&");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{what}: no self test result ({e}) in the page: '{text}'\nchromium stderr:\n{tail}"))
}

fn check(result: &serde_json::Value, what: &str) {
    let errors = result["errors"].as_array().expect("errors list");
    assert!(errors.is_empty(), "{what}: console errors: {errors:?}");
    assert!(result.get("failed").is_none(), "{what}: viewer failed: {result}");
    let (w, h) = (result["width"].as_u64().unwrap(), result["height"].as_u64().unwrap());
    assert!(w >= 200 && h >= 100, "{what}: canvas is {w}x{h}");
    for (i, ink) in result["ink"].as_array().unwrap().iter().enumerate() {
        // A skeleton and its grid cover far more than a few hundred pixels of an 800x560 canvas.
        assert!(ink.as_u64().unwrap() > 1000, "{what}: canvas almost blank at frame {i}: {result}");
    }
    let (tip, wanted) = (result["hover"].as_str().unwrap(), result["hoverWanted"].as_str().unwrap());
    assert!(!wanted.trim().is_empty() && tip.starts_with(wanted), "{what}: hovering a joint shows '{tip}', not its name and track '{wanted}'");
    for control in ["orbited", "panned", "zoomed", "played", "advanced"] {
        assert_eq!(result["controls"][control], true, "{what}: the page was not {control} by its controls: {result}");
    }
    let probe = result["probeError"].as_f64().expect("probe error");
    assert!(probe < 0.01, "{what}: the page decodes positions {probe} levels away from html.rs's quantisation: {result}");
    assert!(result["diff"].as_u64().unwrap() > 200, "{what}: the two frames look the same: {result}");
    for f in result["frames"].as_array().unwrap() {
        assert_ne!(f[0], f[1], "{what}: the self test drew the same frame twice: {result}");
    }
}

#[test]
fn viewer_draws_moving_skeletons_in_chromium() {
    let Some(chromium) = find_chromium() else {
        common::skip("viewer_draws_moving_skeletons_in_chromium", "chromium not found (install Debian's chromium)");
        return;
    };
    let dir = Scratch::new("browser");
    let started = Instant::now();

    // Side by side, coloured by labels whose names try to break out of the page.
    let mut biped = example_track("biped");
    let mut spider = example_track("spider");
    for t in [&mut biped, &mut spider] {
        t.point_labels = Some((0..t.points()).map(|p| Some(p % 3)).collect());
        t.frame_labels = Some((0..t.frames).map(|f| if f < t.frames / 2 { Some(0) } else { None }).collect());
    }
    biped.names[1] = "</script><script>throw new Error('escaped')</script>".to_string();
    let legend = Legend { labels: vec!["left \"<b>\"".to_string(), "</script>".to_string(), "a & b".to_string()] };
    let opts = HtmlOptions { title: "side </title> by side".to_string(), ..HtmlOptions::default() };
    let side = dir.join("side.html");
    std::fs::write(&side, render_html(&[biped, spider], &legend, &opts).unwrap()).unwrap();

    // Overlaid and following the root, no labels.
    let opts = HtmlOptions { overlay: true, follow: true, speed: 0.5, ..HtmlOptions::default() };
    let overlay = dir.join("overlay.html");
    std::fs::write(&overlay, render_html(&[example_track("quadruped"), example_track("centipede")], &Legend::default(), &opts).unwrap()).unwrap();

    let built = started.elapsed();
    // Both browsers at once: the machine's cores mostly wait on browser start-up.
    let a = open(&chromium, &side, &dir.join("profile-side"));
    let b = open(&chromium, &overlay, &dir.join("profile-overlay"));
    let limit = Duration::from_secs(60);
    let side_result = finish(a, limit, "side by side");
    let overlay_result = finish(b, limit, "overlay");
    eprintln!("side by side: {side_result}\noverlay: {overlay_result}\nbrowser test took {:.2?} (pages built in {built:.2?})", started.elapsed());
    check(&side_result, "side by side");
    assert_eq!(side_result["views"], 2);
    check(&overlay_result, "overlay");
    assert_eq!(overlay_result["views"], 1);
}

/// Size and error on real long clips. Measurement, not a gate: run with
/// `cargo test --release --test it render_html -- --ignored --nocapture`.
#[test]
#[ignore]
fn measure_page_size_on_corpus() {
    let Some(data) = common::shared_data("measure_page_size_on_corpus") else { return };
    let files = common::corpus_bvh_files(&data);
    let mut picks: Vec<(usize, PathBuf)> = Vec::new();
    for f in files {
        let head = std::fs::read_to_string(&f).unwrap_or_default();
        let frames = head.lines().find_map(|l| l.trim().strip_prefix("Frames:").and_then(|v| v.trim().parse::<usize>().ok()));
        picks.push((frames.unwrap_or(0), f));
    }
    picks.sort();
    let longest: Vec<Track> = picks.iter().rev().take(3).map(|(_, path)| bvh_track(path)).collect();
    for track in &longest {
        report(track);
    }
    // 5000 frames x 115 points of real motion: copies of the longest clip's skeleton, each
    // shifted in time (so no copy repeats another) but moved onto the first copy's root path (so
    // the body stays one creature in size and the levels as fine as for the clip itself).
    let src = &longest[0];
    let (n, points, frames) = (src.points(), 115, 5000);
    let shift = src.frames / (points / n + 1);
    let mut t = src.clone();
    t.title = format!("{} x{} (5000 x 115)", src.title, points.div_ceil(n));
    t.frames = frames;
    t.names = (0..points).map(|p| format!("{} {}", src.names[p % n], p / n)).collect();
    t.parents = (0..points).map(|p| src.parents[p % n].map(|q| q + p / n * n)).collect();
    t.end_site = (0..points).map(|p| src.end_site[p % n]).collect();
    t.positions = (0..frames)
        .flat_map(|f| (0..points).map(move |p| (f, p)))
        .map(|(f, p)| {
            let copy = p / n;
            let g = (f + copy * shift) % src.frames;
            src.frame(g)[p % n] - src.frame(g)[0] + src.frame(f % src.frames)[0]
        })
        .collect();
    report(&t);
    if let Some(chromium) = find_chromium() {
        let dir = Scratch::new("measure");
        let page = dir.join("long.html");
        std::fs::write(&page, render_html(&[t], &Legend::default(), &HtmlOptions::default()).unwrap()).unwrap();
        let result = finish(open(&chromium, &page, &dir.join("profile")), Duration::from_secs(60), "long");
        check(&result, "long");
        println!("5000 x 115 in Chromium: inflated, decoded and measured in {} ms", result["loadMs"]);
    }
}

fn report(track: &Track) {
    let start = Instant::now();
    let page = render_html(std::slice::from_ref(track), &Legend::default(), &HtmlOptions::default()).unwrap();
    let took = start.elapsed();
    let decoded = decoded_positions(track);
    // Body size as html.rs measures it: the largest single-frame extent.
    let size = (0..track.frames)
        .map(|f| {
            let (mut l, mut h) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in track.frame(f) {
                for a in 0..3 {
                    l[a] = l[a].min(p[a] as f64);
                    h[a] = h[a].max(p[a] as f64);
                }
            }
            (0..3).map(|a| (h[a] - l[a]).powi(2)).sum::<f64>().sqrt()
        })
        .fold(0.0, f64::max);
    // Distance between a point and where the page draws it.
    let err = track.positions.iter().zip(&decoded).map(|(p, d)| (0..3).map(|a| (p[a] as f64 - d[a]).powi(2)).sum::<f64>().sqrt()).fold(0.0, f64::max);
    let pf = track.frames * track.points();
    println!(
        "{}: {} frames x {} points: page {} bytes ({:.2} bytes per point-frame, {:.0} KB scaled to 5000x115), max error {:.3e} = {:.5}% of the body, built in {took:.2?}",
        track.title,
        track.frames,
        track.points(),
        page.len(),
        page.len() as f64 / pf as f64,
        page.len() as f64 / pf as f64 * 5000.0 * 115.0 / 1024.0,
        err,
        100.0 * err / size
    );
}
