//! `whitted lsp` from a real editor: headless Neovim (Debian's package, installed by
//! `.ci/run`) with exactly the documented setup, `editors/nvim/whitted.lua`, opens a broken
//! scene and must show the server's diagnostic at the line and column `whitted check` gives.

use std::path::{Path, PathBuf};
use std::process::Command;

/// What the probe asks Neovim once the file is open: wait for the server's diagnostics,
/// write them as JSON, quit.
const PROBE: &str = r#"
local ok = vim.wait(30000, function() return #vim.diagnostic.get(0) > 0 end, 50)
local out = {}
for _, d in ipairs(vim.diagnostic.get(0)) do
  table.insert(out, { lnum = d.lnum, col = d.col, message = d.message, severity = d.severity })
end
vim.fn.writefile({ vim.fn.json_encode({ waited = ok, diagnostics = out }) }, "diagnostics.json")
vim.cmd("qa!")
"#;

#[test]
fn neovim_shows_the_servers_diagnostic_where_check_puts_it() {
    let nvim = Command::new("nvim").arg("--version").output();
    assert!(
        nvim.is_ok_and(|o| o.status.success()),
        "Neovim is needed for this test: `apt-get install neovim` (.ci/run installs it)"
    );
    let dir = tempfile::tempdir().expect("a temporary directory");
    // `radius = 1`: the error is at the `=`, line 2, column 17 (1-based, as `check` says).
    std::fs::write(
        dir.path().join("broken.scene"),
        "material m { diffuse 0.5 }\nsphere { radius = 1 material m }\n",
    )
    .expect("writable");
    std::fs::write(dir.path().join("probe.lua"), PROBE).expect("writable");
    let binary = PathBuf::from(env!("CARGO_BIN_EXE_whitted"));
    let folder = binary.parent().expect("the binary's folder");
    let path = format!(
        "{}:{}",
        folder.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let setup = Path::new(env!("CARGO_MANIFEST_DIR")).join("editors/nvim/whitted.lua");
    let status = Command::new("nvim")
        .current_dir(dir.path())
        .env("PATH", path)
        // Neovim's own state (its LSP log) stays in the test's folder.
        .env("XDG_STATE_HOME", dir.path())
        .env("XDG_CACHE_HOME", dir.path())
        .args(["--headless", "-u"])
        .arg(&setup)
        .args(["broken.scene", "-c", "luafile probe.lua"])
        .status()
        .expect("Neovim runs");
    assert!(status.success());
    let written =
        std::fs::read_to_string(dir.path().join("diagnostics.json")).expect("the probe wrote");
    let report: serde_json::Value = serde_json::from_str(&written).expect("JSON");
    assert_eq!(report["waited"], true, "no diagnostics arrived: {written}");
    let first = &report["diagnostics"][0];
    // Neovim counts from 0.
    assert_eq!(
        (first["lnum"].as_u64(), first["col"].as_u64()),
        (Some(1), Some(16)),
        "{written}"
    );
    assert_eq!(first["severity"], 1, "an error: {written}");
    let message = first["message"].as_str().unwrap_or_default();
    assert!(
        message.contains("`=` after the property `radius`"),
        "{message}"
    );
    assert!(message.contains("help: write `radius 1`"), "{message}");
}
