//! The ray budget per sample, through the real binary: `render` of the explosion scene
//! (glass that reflects and transmits in a box of mirrors, `min_weight 0`, `max_depth 64`)
//! finishes, writes its image and reports the pixels cut, the first one and the settings
//! that caused it; `--stats` has the same figures; `trace` of that first pixel shows the
//! cut; a scene under the budget gets no report. Time is not asserted (see the limit's doc
//! comment for the figures).

use crate::support::run;
use serde_json::Value;

const SCENE: &str = "scenes/ray-explosion.scene";

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The number after `prefix` in `text`.
fn number_after(text: &str, prefix: &str) -> Option<u64> {
    let start = text.find(prefix)? + prefix.len();
    let digits: String = text[start..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().ok()
}

#[test]
fn the_explosion_scene_renders_cut_at_the_budget_with_a_report() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let image = dir.path().join("explosion.png");
    let image = image.to_str().expect("a UTF-8 path");
    let output = run(&["render", SCENE, "-o", image, "--threads", "2"]);
    let stderr = text(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    // The lint warned first, at `min_weight`.
    assert!(
        stderr.contains("warning: ray_budget: min_weight 0 with material `half_glass`"),
        "{stderr}"
    );
    // Then the report after the render.
    let cut = stderr
        .lines()
        .find(|l| l.contains("pixels were cut"))
        .and_then(|line| number_after(line, "warning: "));
    let Some(cut) = cut else {
        panic!("no report of cut pixels: {stderr}");
    };
    assert!(cut > 1000 && cut <= 64 * 48, "{cut} pixels cut: {stderr}");
    assert!(
        stderr.contains(&format!(
            "warning: {cut} of 3072 pixels were cut at the ray budget of 10000 rays per sample, \
             the first at ("
        )),
        "{stderr}"
    );
    assert!(
        stderr.contains(
            "cause: min_weight 0 at scenes/ray-explosion.scene:6:44 with max_depth 64 at \
             scenes/ray-explosion.scene:6:31 and material `half_glass` \
             (scenes/ray-explosion.scene:10:1), which reflects and transmits (up to 3.7e19 \
             rays a sample)"
        ),
        "{stderr}"
    );
    let decoded = image::open(image).expect("the render wrote a PNG");
    assert_eq!((decoded.width(), decoded.height()), (64, 48));

    // `--stats --json` has the same count and the first pixel, and says nothing on stderr
    // with `--quiet`.
    let output = run(&[
        "render",
        SCENE,
        "-o",
        image,
        "--threads",
        "2",
        "--stats=json",
        "--quiet",
    ]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert!(!text(&output.stderr).contains("pixels were cut"));
    let stats: Value = serde_json::from_slice(&output.stdout).expect("JSON stats");
    assert_eq!(stats["pixels_cut_at_ray_budget"], cut);
    assert_eq!(stats["ray_budget_per_sample"], 10000);
    let first = &stats["first_pixel_cut_at_ray_budget"];
    let (x, y) = (first[0].as_u64(), first[1].as_u64());
    let (Some(x), Some(y)) = (x, y) else {
        panic!("no first pixel: {stats}");
    };
    assert!(
        stderr.contains(&format!("the first at ({x}, {y})")),
        "{stderr}"
    );

    // That pixel's ray tree shows the cut: the same code path stops at the same place.
    let pixel = format!("{x},{y}");
    let output = run(&["trace", SCENE, "--pixel", &pixel]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let trace = text(&output.stdout);
    assert!(
        trace.contains("ray budget (the sample had cast its 10000 rays"),
        "{}",
        &trace[..trace.len().min(3000)]
    );
    // Rows above it and pixels before it on its row were not cut.
    let before = if x > 0 {
        Some((x - 1, y))
    } else {
        y.checked_sub(1).map(|y| (63, y))
    };
    if let Some((bx, by)) = before {
        let output = run(&["trace", SCENE, "--pixel", &format!("{bx},{by}"), "--json"]);
        assert!(output.status.success(), "{}", text(&output.stderr));
        assert!(!text(&output.stdout).contains("\"ray_budget\""));
    }
}

#[test]
fn a_scene_under_the_budget_gets_no_report() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let image = dir.path().join("whitted.png");
    let image = image.to_str().expect("a UTF-8 path");
    let output = run(&[
        "render",
        "scenes/whitted.scene",
        "-o",
        image,
        "--width",
        "64",
        "--height",
        "48",
        "--stats=json",
    ]);
    let stderr = text(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(!stderr.contains("ray budget"), "{stderr}");
    let stats: Value = serde_json::from_slice(&output.stdout).expect("JSON stats");
    assert_eq!(stats["pixels_cut_at_ray_budget"], 0);
    assert_eq!(stats["first_pixel_cut_at_ray_budget"], Value::Null);
}
