//! `kinergy view` in a real browser: headless Chromium opens the page, and what the page
//! reports it loaded and shows is checked against the files and against Kinergy's own forward
//! kinematics projected with the page's camera; a screenshot at a fixed frame shows the figures
//! where they should be. Clips of different frame rates stay in step by time.
//!
//! Chromium is Debian's `chromium` (`KINERGY_CHROMIUM` names another). Where none is installed
//! the browser tests skip, saying so — unless `KINERGY_REQUIRE_BROWSER=1` (CI), where they fail.

mod common;
use common::{fixture, kinergy, s, stderr, synthetic};

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use kinergy_motion::nalgebra::{Matrix4, Point3, Vector4};

/// The browser, or `None` (having said why) where the tests may skip.
fn chromium() -> Option<PathBuf> {
    let named = std::env::var_os("KINERGY_CHROMIUM").map(PathBuf::from);
    let found = named.or_else(|| {
        ["chromium", "chromium-browser", "google-chrome"]
            .iter()
            .flat_map(|name| {
                std::env::var_os("PATH")
                    .map(|p| std::env::split_paths(&p).collect::<Vec<_>>())
                    .unwrap_or_default()
                    .into_iter()
                    .map(move |dir| dir.join(name))
            })
            .find(|p| p.is_file())
    });
    if found.is_none() {
        let why = "no Chromium (apt-get install chromium, or KINERGY_CHROMIUM=PATH)";
        assert!(
            std::env::var("KINERGY_REQUIRE_BROWSER").as_deref() != Ok("1"),
            "KINERGY_REQUIRE_BROWSER=1 but {why}"
        );
        eprintln!("skipping the browser test: {why}");
    }
    found
}

/// Runs headless Chromium on `url` with `extra` arguments (its own empty profile, no network
/// chatter, software WebGL); returns what it printed on stdout.
fn browse(browser: &Path, profile: &Path, url: &str, extra: &[&str]) -> String {
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--window-size=1000,800",
            "--virtual-time-budget=4000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .output()
        .expect("run chromium");
    assert!(out.status.success(), "chromium failed: {}", stderr(&out));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The `data-*` attributes of the dumped DOM's `<body>`, unescaped.
fn body_data(dom: &str) -> HashMap<String, String> {
    let start = dom.find("<body").expect("a <body>");
    let tag = &dom[start..start + dom[start..].find('>').expect("the tag ends")];
    let mut out = HashMap::new();
    let mut rest = tag;
    while let Some(i) = rest.find(" data-") {
        rest = &rest[i + 6..];
        let eq = rest.find("=\"").expect("an attribute value");
        let name = rest[..eq].to_string();
        rest = &rest[eq + 2..];
        let end = rest.find('"').expect("the value ends");
        let value = rest[..end]
            .replace("&quot;", "\"")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&#39;", "'")
            .replace("&amp;", "&");
        out.insert(name, value);
        rest = &rest[end + 1..];
    }
    out
}

fn parse<T: serde::de::DeserializeOwned>(data: &HashMap<String, String>, key: &str) -> T {
    let text = data
        .get(key)
        .unwrap_or_else(|| panic!("the page reports no data-{key}: {data:?}"));
    serde_json::from_str(text).unwrap_or_else(|e| panic!("data-{key} = {text}: {e}"))
}

/// Three clips: the synthetic r09 (60 Hz), a 30 Hz synthetic reach made here, and the CMU
/// fixture (a 31-joint rig at 60 Hz).
fn clips(dir: &Path) -> Vec<PathBuf> {
    let slow = dir.join("slow");
    let out = kinergy(&[
        "synth",
        "--persons",
        "1",
        "--reaches",
        "1",
        "--frame-rate",
        "30",
        "-o",
        s(&slow),
        "-q",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    vec![
        synthetic("r09.bvh"),
        slow.join("p01/r01.bvh"),
        fixture("006_14.bvh"),
    ]
}

/// Each clip's world positions per frame and frame time, by Kinergy's own reading and FK.
fn truth(clips: &[PathBuf]) -> Vec<(Vec<Vec<Point3<f64>>>, f64)> {
    clips
        .iter()
        .map(|path| {
            let (clip, _) = kinergy_motion::read_clip(path, &Default::default()).expect("read");
            let joints = clip.skeleton().joint_count();
            let world = clip.world_positions().expect("fk");
            (
                world.chunks(joints).map(<[_]>::to_vec).collect(),
                clip.frame_time(),
            )
        })
        .collect()
}

#[test]
fn the_page_shows_every_clip_at_the_frame_asked_where_kinergys_fk_puts_it() {
    let Some(browser) = chromium() else { return };
    let dir = tempfile::tempdir().expect("tmp");
    let clips = clips(dir.path());
    let page = dir.path().join("view.html");
    let mut args = vec!["view"];
    args.extend(clips.iter().map(|c| s(c)));
    args.extend(["--target", "0.2,1.0,0.5", "-o", s(&page)]);
    let out = kinergy(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let truth = truth(&clips);

    // Seek to the first clip's frame 40: each clip shows its frame nearest that time.
    // The 3-D view at a fixed size: the DOM dump and the screenshot lay the page out alike.
    let url = format!("file://{}#frame=40,view=900x450", page.display());
    let dom = browse(&browser, &dir.path().join("profile"), &url, &["--dump-dom"]);
    let data = body_data(&dom);
    assert_eq!(data.get("ready").map(String::as_str), Some("1"), "{data:?}");
    assert_eq!(data.get("webgl").map(String::as_str), Some("yes"));
    assert_eq!(data.get("clips").map(String::as_str), Some("3"));
    let joints: Vec<usize> = parse(&data, "joints");
    let frames: Vec<usize> = parse(&data, "frames");
    assert_eq!(
        joints,
        truth.iter().map(|t| t.0[0].len()).collect::<Vec<_>>()
    );
    assert_eq!(frames, truth.iter().map(|t| t.0.len()).collect::<Vec<_>>());
    let time: f64 = parse(&data, "time");
    assert!((time - 40.0 * truth[0].1).abs() < 1e-9, "time {time}");
    let shown: Vec<usize> = parse(&data, "shown");
    let expected: Vec<usize> = truth
        .iter()
        .map(|(poses, dt)| ((time / dt).round() as usize).min(poses.len() - 1))
        .collect();
    assert_eq!(shown, expected, "the frames shown at {time} s");
    assert_eq!(shown[0], 40);
    assert_ne!(shown[1], 40, "the 30 Hz clip shows its own frame, by time");

    // Every joint where the page's camera puts Kinergy's FK of that frame.
    let camera: Vec<f64> = parse(&data, "camera");
    let m = Matrix4::from_column_slice(&camera);
    let viewport: Vec<f64> = data["viewport"]
        .split(',')
        .map(|v| v.parse().expect("number"))
        .collect();
    let (w, h) = (viewport[0], viewport[1]);
    let project = |p: &Point3<f64>| {
        let c = m * Vector4::new(p.x, p.y, p.z, 1.0);
        (((c.x / c.w) + 1.0) / 2.0 * w, (1.0 - c.y / c.w) / 2.0 * h)
    };
    let screen: Vec<Vec<(f64, f64)>> = parse(&data, "screen");
    let mut worst = 0.0f64;
    for (k, ((poses, _), drawn)) in truth.iter().zip(&screen).enumerate() {
        let pose = &poses[shown[k]];
        assert_eq!(pose.len(), drawn.len());
        for (p, d) in pose.iter().zip(drawn) {
            let (x, y) = project(p);
            worst = worst.max((x - d.0).hypot(y - d.1));
            assert!(
                (0.0..w).contains(&x) && (0.0..h).contains(&y),
                "clip {k}: a joint off the screen at ({x:.0}, {y:.0})"
            );
        }
    }
    // Positions go to the page to 0.1 mm: well under a pixel at this distance.
    assert!(worst < 0.5, "a joint {worst:.2} px from Kinergy's FK");

    // The screenshot at that frame: each figure's joints lie on drawn (coloured) pixels.
    let shot = dir.path().join("shot.png");
    browse(
        &browser,
        &dir.path().join("profile2"),
        &url,
        &[&format!("--screenshot={}", shot.display())],
    );
    let image = image::open(&shot).expect("screenshot").to_rgb8();
    let offset: Vec<f64> = parse(&data, "canvas");
    let coloured = |x: f64, y: f64| {
        let (cx, cy) = (
            (x + offset[0]).round() as i64,
            (y + offset[1]).round() as i64,
        );
        (-2..=2).any(|dx| {
            (-2..=2).any(|dy| {
                let (px, py) = (cx + dx, cy + dy);
                px >= 0
                    && py >= 0
                    && (px as u32) < image.width()
                    && (py as u32) < image.height()
                    && {
                        let [r, g, b] = image.get_pixel(px as u32, py as u32).0;
                        r.max(g).max(b) - r.min(g).min(b) > 60
                    }
            })
        })
    };
    for (k, drawn) in screen.iter().enumerate() {
        let hits = drawn.iter().filter(|d| coloured(d.0, d.1)).count();
        assert!(
            hits * 10 >= drawn.len() * 9,
            "clip {k}: {hits} of {} joints on drawn pixels",
            drawn.len()
        );
    }
    // And the background is the background: the top-left corner of the 3-D view is white.
    let [r, g, b] = image
        .get_pixel(offset[0] as u32 + 3, offset[1] as u32 + 3)
        .0;
    assert!(r > 240 && g > 240 && b > 240, "background ({r}, {g}, {b})");
}

/// `compare -o DIR` writes `DIR/view.html`: the first reach captured and as each model moves
/// it, loaded in the browser with every clip's frames, Fig. 3 under it.
#[test]
fn compares_page_holds_the_capture_and_each_models_motion() {
    let Some(browser) = chromium() else { return };
    let dir = tempfile::tempdir().expect("tmp");
    let out = dir.path().join("compare");
    let o = kinergy(&[
        "compare",
        s(&synthetic("r09.bvh")),
        "--models",
        "sa,sc",
        "--budget",
        "40",
        "--no-baselines",
        "-o",
        s(&out),
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let page = out.join("view.html");
    let html = std::fs::read_to_string(&page).expect("view.html");
    assert!(html.contains("Fig. 3"), "the figure under the page");
    let url = format!("file://{}#frame=10,view=900x450", page.display());
    let dom = browse(&browser, &dir.path().join("profile"), &url, &["--dump-dom"]);
    let data = body_data(&dom);
    assert_eq!(data.get("ready").map(String::as_str), Some("1"), "{data:?}");
    assert_eq!(data.get("clips").map(String::as_str), Some("3"));
    let frames: Vec<usize> = parse(&data, "frames");
    // The captured reach and the two syntheses of it: at least the reach's frames each.
    assert!(frames.iter().all(|&f| f >= frames[0]), "{frames:?}");
    let shown: Vec<usize> = parse(&data, "shown");
    assert_eq!(shown, vec![10, 10, 10], "one rate, one clock");
}

#[test]
fn a_bad_clip_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().expect("tmp");
    let bad = dir.path().join("bad.bvh");
    std::fs::write(&bad, "HIERARCHY\nROOT Hips\n{\n").expect("write");
    let page = dir.path().join("view.html");
    let out = kinergy(&["view", s(&synthetic("r09.bvh")), s(&bad), "-o", s(&page)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("bad.bvh"), "{}", stderr(&out));
    assert!(!page.exists(), "nothing written");
    let out = kinergy(&[
        "view",
        s(&synthetic("r09.bvh")),
        "-o",
        s(&dir.path().join("v.png")),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains(".html"), "{}", stderr(&out));
}
