//! `whitted grade --class`'s HTML report in a real browser: headless Chromium (Debian's
//! package, installed by `.ci/run`) loads `index.html` from disk and takes a screenshot,
//! and the screenshot must show the pictures (the reference's sky colour, which only the
//! picture files hold), so the page's relative image paths and the PNGs themselves work.

use std::path::PathBuf;
use std::process::Command;

use crate::support::ok;

#[test]
fn the_class_report_shows_its_pictures_in_chromium() {
    let chromium = Command::new("chromium").arg("--version").output();
    assert!(
        chromium.is_ok_and(|o| o.status.success()),
        "this test needs Debian's chromium (apt-get install chromium; .ci/run installs it)"
    );
    let dir = tempfile::tempdir().unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let scene = root.join("scenes/mit6837/student-bugs.txt");
    let line = format!(
        "raytracer -input {} -size 96 72 -output a.tga -shadows -bounces 2",
        scene.display()
    );
    let commands = dir.path().join("commands.txt");
    std::fs::write(&commands, format!("{line}\n")).unwrap();
    let class = dir.path().join("class");
    for (student, set) in [("ada", "ambient=0"), ("bob", "epsilon=0")] {
        let folder = class.join(student);
        std::fs::create_dir_all(&folder).unwrap();
        let out = folder.join("a.tga");
        let mut args: Vec<&str> = vec!["mit6837"];
        let words: Vec<&str> = line.split_whitespace().skip(1).collect();
        let out = out.to_str().unwrap();
        for (i, word) in words.iter().enumerate() {
            args.push(if i > 0 && words[i - 1] == "-output" {
                out
            } else {
                word
            });
        }
        args.extend(["--set", set]);
        ok(&args);
    }
    let report = dir.path().join("report");
    ok(&[
        "grade",
        "--class",
        class.to_str().unwrap(),
        "--commands",
        commands.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    let shot = dir.path().join("shot.png");
    let profile = dir.path().join("profile");
    let status = Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--window-size=1200,1400",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", report.join("index.html").display()))
        .output()
        .expect("chromium runs");
    assert!(
        status.status.success() && shot.exists(),
        "chromium failed: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    let image = image::open(&shot).unwrap().to_rgb8();
    // The scene's background, 0.2 0.3 0.45, as the course's 8-bit linear values.
    let sky = [51u8, 77, 115];
    let near = |p: &image::Rgb<u8>| p.0.iter().zip(sky).all(|(a, b)| a.abs_diff(b) <= 3);
    let sky_pixels = image.pixels().filter(|p| near(p)).count();
    // Two students, three panels with the sky each (the residual is dark).
    assert!(
        sky_pixels > 2 * 3 * 300,
        "the screenshot shows {sky_pixels} sky pixels: the pictures did not load"
    );
}
