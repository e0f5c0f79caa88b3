//! The tree-sitter grammar of the scene language (`grammar.js`, generated into `parser.c`) and its editor queries.
//!
//! ```
//! let mut parser = tree_sitter::Parser::new();
//! parser.set_language(&tree_sitter_whitted::LANGUAGE.into()).unwrap();
//! let tree = parser.parse("sphere { radius 1 }", None).unwrap();
//! assert!(!tree.root_node().has_error());
//! ```

// The one foreign call: the generated parser's entry point, which returns a pointer to its
// static language table. Calling it has no preconditions.
#![allow(unsafe_code)]

use tree_sitter_language::LanguageFn;

extern "C" {
    fn tree_sitter_whitted() -> *const ();
}

/// The language, for `tree_sitter::Parser::set_language(&LANGUAGE.into())`.
pub const LANGUAGE: LanguageFn = unsafe { LanguageFn::from_raw(tree_sitter_whitted) };

/// The highlight query (`queries/highlights.scm`): captures such as `@keyword`, `@number`.
pub const HIGHLIGHTS_QUERY: &str = include_str!("../../queries/highlights.scm");
/// The folding query (`queries/folds.scm`).
pub const FOLDS_QUERY: &str = include_str!("../../queries/folds.scm");
/// The indentation query (`queries/indents.scm`, in nvim-treesitter's capture names).
pub const INDENTS_QUERY: &str = include_str!("../../queries/indents.scm");
/// The node types the parser makes (`src/node-types.json`).
pub const NODE_TYPES: &str = include_str!("../../src/node-types.json");
