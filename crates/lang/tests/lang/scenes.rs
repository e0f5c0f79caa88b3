//! Every scene in the repository's scenes/ folder compiles without errors, through a loader
//! that reads the disk as the CLI does.

use std::path::{Path, PathBuf};

use whitted_lang::{compile_file, render_diagnostics, CompileOptions, SourceLoader};

struct DiskLoader;

impl SourceLoader for DiskLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

fn scene_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            scene_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "scene") {
            out.push(path);
        }
    }
}

#[test]
fn every_scene_in_the_repository_compiles() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut files = Vec::new();
    scene_files(&root, &mut files);
    assert!(
        files.iter().any(|f| f.ends_with("bench/grid.scene")),
        "scenes/bench/grid.scene is missing"
    );
    for file in files {
        let compilation = compile_file(&file, &mut DiskLoader, &CompileOptions::default());
        assert!(
            !compilation.has_errors(),
            "{} does not compile:\n{}",
            file.display(),
            render_diagnostics(&compilation.sources, &compilation.diagnostics, false)
        );
    }
}

#[test]
fn the_benchmark_grid_follows_its_size_constant() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/bench/grid.scene");
    let options = CompileOptions {
        defines: vec![("N".to_string(), "7".to_string())],
        ..CompileOptions::default()
    };
    let compilation = compile_file(&path, &mut DiskLoader, &options);
    let scene = compilation.scene.expect("grid.scene compiles with -D N=7");
    // 49 spheres and the floor.
    assert_eq!(scene.objects.len(), 50);
}
