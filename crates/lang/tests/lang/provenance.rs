//! The instantiation stack each object keeps (issue 12, item 2): loop values (`for`, with
//! and without `step`), calls with their argument values, imports, and nothing for objects
//! written at the top level of the root file.

use whitted_ir::{Handle, Scene};
use whitted_lang::CompileOptions;

use crate::support::{compile, compile_with, MapLoader};

fn scene_of(compilation: whitted_lang::Compilation) -> Scene {
    assert!(
        compilation.scene.is_some(),
        "{:#?}",
        compilation.diagnostics
    );
    compilation.scene.expect("compiles").into_inner()
}

/// The stack of every object, in arena order, as `whitted ir` writes it.
fn stacks(scene: &Scene) -> Vec<String> {
    (0..scene.objects.len())
        .map(|i| {
            scene
                .provenance
                .describe(Handle::from_index(i), &scene.sources)
        })
        .collect()
}

#[test]
fn loop_values_through_a_function_called_in_a_loop_inside_an_import() {
    let mut loader = MapLoader::with(&[(
        "lib.scene",
        "fn ring(n, r) {\n    for i in 0..n {\n        sphere { center <r, i, 0> radius 0.1 }\n    }\n}\n",
    )]);
    let main = "import \"lib.scene\"\nfor k in 0..3 {\n    ring(12, 2)\n}\n";
    let scene = scene_of(compile_with(main, &mut loader, &CompileOptions::default()));
    let stacks = stacks(&scene);
    assert_eq!(stacks.len(), 36);
    assert_eq!(
        stacks[12 + 7],
        "i = 7 at lib.scene:2:5, import at test.scene:1:1, ring(12, 2) at test.scene:3:5, \
         k = 1 at test.scene:2:1"
    );
    // One frame per iteration: neighbours differ in their own loop's value only.
    assert!(stacks[12 + 8].starts_with("i = 8 at lib.scene:2:5, import"));
    assert!(stacks[2 * 12].ends_with("k = 2 at test.scene:2:1"));
}

#[test]
fn objects_at_the_top_level_of_the_root_file_have_no_stack() {
    let scene = scene_of(compile(
        "sphere { }\nfor i in 0..2 { sphere { } }\nsphere { }\n",
    ));
    assert_eq!(
        stacks(&scene),
        ["", "i = 0 at test.scene:2:1", "i = 1 at test.scene:2:1", ""]
    );
}

#[test]
fn an_imported_files_own_objects_show_the_import_line() {
    let mut loader = MapLoader::with(&[
        ("a.scene", "import \"b.scene\"\nsphere { }\n"),
        ("b.scene", "box { }\n"),
    ]);
    let scene = scene_of(compile_with(
        "\nimport \"a.scene\"\nsphere { }\n",
        &mut loader,
        &CompileOptions::default(),
    ));
    assert_eq!(
        stacks(&scene),
        [
            "import at a.scene:1:1, import at test.scene:2:1",
            "import at test.scene:2:1",
            ""
        ]
    );
}

#[test]
fn stepped_loops_and_arguments_of_every_kind() {
    let scene = scene_of(compile(
        "fn bead(p, label, on, list) { sphere { center p } }\n\
         for x in 10..0 step -5 {\n    bead(<x, 0.5, -1>, \"b{x}\", true, [1, 2])\n}\n\
         let w = 0;\nwhile w < 1 { w = w + 1; box { } }\n",
    ));
    assert_eq!(
        stacks(&scene),
        [
            "bead(<10, 0.5, -1>, \"b10\", true, [1, 2]) at test.scene:3:5, x = 10 at test.scene:2:1",
            "bead(<5, 0.5, -1>, \"b5\", true, [1, 2]) at test.scene:3:5, x = 5 at test.scene:2:1",
            // A `while` loop has no variable to show.
            "",
        ]
    );
}

#[test]
fn arguments_are_the_values_the_call_received() {
    // Arguments are shown evaluated, whatever expressions the call wrote.
    let scene = scene_of(compile(
        "let a = 2;\nfn f(n) {\n    let m = n * 10;\n    sphere { radius m }\n}\nf(a + 1)\n",
    ));
    assert_eq!(stacks(&scene), ["f(3) at test.scene:6:1"]);
}

#[test]
fn recursion_shows_every_call_and_children_share_their_parents_frame() {
    let scene = scene_of(compile(
        "fn tree(d) {\n    if d > 0 {\n        group { sphere { } box { } }\n        tree(d - 1)\n    }\n}\ntree(2)\n",
    ));
    let stacks = stacks(&scene);
    // tree(2) makes sphere, box and their group, then tree(1) makes three more.
    assert_eq!(stacks[0], "tree(2) at test.scene:7:1");
    assert_eq!(stacks[1], stacks[0]);
    assert_eq!(stacks[2], stacks[0]);
    assert_eq!(
        stacks[3],
        "tree(1) at test.scene:4:9, tree(2) at test.scene:7:1"
    );
    assert_eq!(
        scene.provenance.frame_of(Handle::from_index(3)),
        scene.provenance.frame_of(Handle::from_index(5))
    );
}
