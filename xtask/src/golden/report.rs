//! The HTML report of a golden run: a table of every scene, and for each failure the
//! expected, actual, difference and FLIP images side by side, and ray-tree diffs.

use std::fmt::Write;

/// What the report shows of one scene.
pub struct SceneReport {
    pub name: String,
    pub figures: Option<super::compare::Comparison>,
    /// Set when the image failed: file names (relative to the report) of the four images.
    pub images: Option<[String; 4]>,
    /// Why the scene could not be compared (no reference, the render failed).
    pub problem: Option<String>,
    /// Ray trees that changed: (pixel label, unified diff).
    pub tree_diffs: Vec<(String, String)>,
}

impl SceneReport {
    pub fn passed(&self) -> bool {
        self.problem.is_none()
            && self.tree_diffs.is_empty()
            && self.figures.as_ref().is_some_and(|f| f.passed)
    }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

pub fn html(scenes: &[SceneReport]) -> String {
    let mut out = String::new();
    let failed = scenes.iter().filter(|s| !s.passed()).count();
    let _ = write!(
        out,
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>whitted golden report</title>\n\
         <style>body{{font-family:sans-serif;background:#222;color:#ddd}} table{{border-collapse:collapse}}\
         td,th{{padding:2px 8px;border-bottom:1px solid #444;text-align:right}} td:first-child{{text-align:left}}\
         .fail{{color:#f66}} .pass{{color:#6c6}} img{{image-rendering:pixelated;width:320px;margin:4px}}\
         figure{{display:inline-block;margin:0}} figcaption{{text-align:center}} pre{{background:#111;padding:8px;overflow:auto}}\
         .del{{color:#f88}} .ins{{color:#8f8}}</style></head><body>\n\
         <h1>whitted golden report</h1><p>{failed} of {} scenes failed.</p>\n",
        scenes.len()
    );
    out.push_str("<table><tr><th>scene</th><th>max error</th><th>mean error</th><th>share over tolerance</th><th>mean FLIP</th><th>result</th></tr>\n");
    for s in scenes {
        let (max, mean, share, flip) = match &s.figures {
            Some(f) => (
                format!("{:.4}", f.max_error),
                format!("{:.5}", f.mean_error),
                format!("{:.3}%", f.failing_share * 100.0),
                format!("{:.4}", f.mean_flip),
            ),
            None => Default::default(),
        };
        let result = if s.passed() {
            "<span class=pass>pass</span>"
        } else {
            "<span class=fail>FAIL</span>"
        };
        let _ = writeln!(
            out,
            "<tr><td><a href=\"#{0}\">{0}</a></td><td>{max}</td><td>{mean}</td><td>{share}</td><td>{flip}</td><td>{result}</td></tr>",
            escape(&s.name)
        );
    }
    out.push_str("</table>\n");
    for s in scenes.iter().filter(|s| !s.passed()) {
        let _ = writeln!(out, "<h2 id=\"{0}\" class=fail>{0}</h2>", escape(&s.name));
        if let Some(problem) = &s.problem {
            let _ = writeln!(out, "<p>{}</p>", escape(problem));
        }
        if let Some(mismatch) = s.figures.as_ref().and_then(|f| f.mismatch.as_ref()) {
            let _ = writeln!(out, "<p>{}</p>", escape(mismatch));
        }
        if let Some(images) = &s.images {
            for (file, caption) in images.iter().zip([
                "expected",
                "actual",
                "difference (x8, red = over tolerance)",
                "FLIP error",
            ]) {
                let _ = writeln!(
                    out,
                    "<figure><a href=\"{0}\"><img src=\"{0}\"></a><figcaption>{caption}</figcaption></figure>",
                    escape(file)
                );
            }
        }
        for (pixel, diff) in &s.tree_diffs {
            let _ = writeln!(out, "<h3>ray tree of pixel {}</h3><pre>", escape(pixel));
            for line in diff.lines() {
                let class = match line.chars().next() {
                    Some('-') => " class=del",
                    Some('+') => " class=ins",
                    _ => "",
                };
                let _ = writeln!(out, "<span{class}>{}</span>", escape(line));
            }
            out.push_str("</pre>\n");
        }
    }
    out.push_str("</body></html>\n");
    out
}
