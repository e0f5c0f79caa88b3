//! What an editor asks of the language: the properties each kind of block takes (from the
//! property table, with their docs), an index of a compiled text (written properties by
//! block, names to their definitions, the outline), and where a cursor is in a text that may
//! not parse (`cursor`).
//!
//! The language server (crates/lsp) turns these into protocol messages; everything that
//! knows the language's words and rules stays here, so the server cannot drift from the
//! compiler.

pub mod cursor;
pub(crate) mod index;
pub mod view;

use std::collections::HashMap;

use whitted_ir::setting_rows::SETTINGS;
use whitted_ir::Span;

use crate::properties::{Kind, Prop, ROWS};
use crate::schema::{CameraTag, Context, LightTag, ObjectTag};

/// A kind of block, as the compiler's property table knows it: a sphere, the settings, a
/// point light, a material, ...
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockKind(pub(crate) Context);

impl BlockKind {
    /// "a sphere", "the settings", "a material", ...
    pub fn describe(self) -> String {
        self.0.describe()
    }

    /// Whether the block holds statements (a file's top level, a function, a loop) rather
    /// than properties.
    pub fn is_statements(self) -> bool {
        self.0.is_statements()
    }

    /// The properties this block accepts, in the docs' order.
    pub fn properties(self) -> Vec<PropertyDoc> {
        self.0
            .properties()
            .into_iter()
            .filter_map(|prop| self.doc(prop))
            .collect()
    }

    /// The property called `name` in this block, if the block accepts it.
    pub fn property(self, name: &str) -> Option<PropertyDoc> {
        self.doc(self.0.property_named(name)?)
    }

    fn doc(self, prop: Prop) -> Option<PropertyDoc> {
        let row = ROWS
            .iter()
            .find(|row| row.prop == prop && crate::properties::row_accepts(row, self.0))?;
        // A setting's documentation is the IR's settings table, which the language's row
        // only repeats (a test keeps them equal); the editor reads the source.
        let setting = (self.0 == Context::Settings)
            .then(|| SETTINGS.iter().find(|s| s.name == prop.name()))
            .flatten();
        Some(PropertyDoc {
            name: prop.name(),
            kind: describe_kind(row.kind),
            default: setting.map_or(row.default, |s| s.default),
            doc: setting.map_or(row.doc, |s| s.doc),
            words: prop.words(),
            is_material: row.kind == Kind::MaterialValue,
            is_flag: row.kind == Kind::Flag,
            repeatable: prop.is_transform(),
        })
    }
}

/// One property as an editor shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct PropertyDoc {
    pub name: &'static str,
    /// What it takes, in words: "a number from 0 to 1", "one of `opaque`, `filtered`, `none`".
    pub kind: String,
    /// The default as the docs write it; empty when there is none.
    pub default: &'static str,
    pub doc: &'static str,
    /// The words it takes, when its value is a word.
    pub words: Option<&'static [&'static str]>,
    /// Whether its value is a material (a name after `material`).
    pub is_material: bool,
    /// Whether it takes no value (`open`).
    pub is_flag: bool,
    /// Whether a block may give it more than once (the transforms).
    pub repeatable: bool,
}

/// A number for the docs: `1` rather than `1.0`, and "any" for an unbounded end.
fn number(value: f64) -> String {
    if value.is_infinite() {
        if value > 0.0 { "any" } else { "-any" }.to_string()
    } else {
        format!("{value}")
    }
}

/// The value a property takes, in the words the docs use.
fn describe_kind(kind: Kind) -> String {
    match kind {
        Kind::Number { min, open, max } => {
            let low = if open { "above" } else { "from" };
            match (min.is_infinite(), max.is_infinite()) {
                (true, true) => "a number".to_string(),
                (false, true) => format!("a number {low} {}", number(min)),
                (true, false) => format!("a number up to {}", number(max)),
                (false, false) => format!("a number {low} {} to {}", number(min), number(max)),
            }
        }
        Kind::Whole { min, max } => {
            if max.is_infinite() {
                format!("a whole number from {}", number(min))
            } else {
                format!("a whole number from {} to {}", number(min), number(max))
            }
        }
        Kind::Vector => "a vector (a position)".to_string(),
        Kind::Direction => "a direction (a vector that is not zero)".to_string(),
        Kind::Color => "a colour (a vector, or one number for a grey)".to_string(),
        Kind::LightColor => "a colour of light".to_string(),
        Kind::ColorOrPattern => "a colour, or a pattern with an optional block".to_string(),
        Kind::Attenuation => "`<constant, linear, quadratic>`, not all zero".to_string(),
        Kind::Word(words) => {
            let quoted: Vec<String> = words.iter().map(|w| format!("`{w}`")).collect();
            format!("one of {}", quoted.join(", "))
        }
        Kind::Flag => "no value".to_string(),
        Kind::MaterialValue => "a material".to_string(),
        Kind::Points(n) => format!("{n} vectors, separated by commas"),
        Kind::Numbers(n) => format!("{n} numbers, as numbers and vectors"),
        Kind::Transform => "a transform".to_string(),
        Kind::ShapeParameter => "a value the shape checks with its other parameters".to_string(),
        Kind::Text => "a string".to_string(),
        Kind::Bool => "`true` or `false`".to_string(),
    }
}

/// The file an `import "name"` in the file at `importer` reads: the path the compiler asks
/// its loader for (and names the file by in its source map).
pub fn import_target(importer: &std::path::Path, name: &str) -> std::path::PathBuf {
    let folder = importer.parent().unwrap_or(std::path::Path::new(""));
    crate::compile::normalize(&folder.join(name))
}

/// What may start a statement in a block of statements, each with a few words on it: the
/// keywords (those only a file's top level or a function takes, there only), then every kind
/// of object.
pub(crate) fn statement_words(
    top_level: bool,
    in_function: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut words = Vec::new();
    if top_level {
        words.extend([
            (
                "import",
                "read another scene file's definitions and objects",
            ),
            ("settings", "the render's settings"),
            ("camera", "the camera: `camera perspective { ... }`"),
        ]);
    }
    words.extend([
        ("light", "a light: `light point { ... }`"),
        ("material", "a named material: `material glass { ... }`"),
        ("let", "a binding that may change: `let n = 3;`"),
        ("const", "a constant (`-D` may replace it): `const n = 3;`"),
        ("fn", "a function: `fn ring(n) { ... }`"),
        ("for", "a loop: `for i in 0..n { ... }`"),
        ("while", "a loop while a condition holds"),
        ("if", "a condition: `if x > 0 { ... } else { ... }`"),
    ]);
    if in_function {
        words.push(("return", "the function's value"));
    }
    words.extend(ObjectTag::ALL.iter().map(|tag| (tag.name(), "an object")));
    words
}

/// The block kind opened by a statement whose first words are `words` (`sphere`,
/// `light spot`, `camera perspective`, `settings`, `material`), if it is one that takes
/// properties.
pub(crate) fn block_named(words: &[&str]) -> Option<BlockKind> {
    let context = match words {
        ["settings", ..] => Context::Settings,
        ["material", ..] => Context::Material,
        ["camera", kind, ..] => {
            Context::Camera(CameraTag::ALL.into_iter().find(|t| t.name() == *kind)?)
        }
        ["light", kind, ..] => {
            Context::Light(LightTag::ALL.into_iter().find(|t| t.name() == *kind)?)
        }
        [kind, ..] => Context::Object(ObjectTag::from_name(kind)?),
        [] => return None,
    };
    Some(BlockKind(context))
}

/// An index of a compiled text: what the editor asks about, located by span in the
/// compilation's source map.
#[derive(Clone, Debug, Default)]
pub struct Index {
    /// Every block that takes properties, with the properties written in it.
    pub blocks: Vec<BlockFacts>,
    /// Each name that means a definition in the scene: (use, definition).
    pub links: Vec<(Span, Span)>,
    /// The outline: materials, lights, objects, functions, settings, camera, bindings.
    pub symbols: Vec<Symbol>,
    /// Every definition of a name (used or not), by the span of its name.
    pub definitions: Vec<Definition>,
    /// What a definition is worth showing, by the span of its name: a function's signature
    /// (`fn ring(n, r)`), and from evaluation a binding's value, a loop's range, a
    /// material's properties (see [`Shown`]).
    pub shown: HashMap<Span, Shown>,
    /// Each object's name written as plain text (`sphere "ball" { ... }`: no `{name}` holes,
    /// no escapes), in the order the files' statements are written: the span of its string
    /// literal (with the quotes) and the name. Nothing in the language refers to an object by
    /// its name; the objects that share one are what explain's queries (`hit("ball")`) and
    /// the debugger call by it.
    pub object_names: Vec<(Span, String)>,
    /// Each file a string names: an `import`'s path and a mesh's `file` written as a plain
    /// string: the span of the literal (with the quotes) and the path as written (relative
    /// to the file the literal is in, as the compiler reads it: see [`import_target`]).
    pub paths: Vec<(Span, String)>,
}

/// A name's definition: where its name is written and what it defines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Definition {
    pub span: Span,
    pub kind: DefinitionKind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DefinitionKind {
    Constant,
    Let,
    Material,
    Function,
    Parameter,
    LoopVariable,
}

impl DefinitionKind {
    /// "a constant", "a `let` binding", ...: as the compiler's messages say it.
    pub fn describe(self) -> &'static str {
        match self {
            DefinitionKind::Constant => "a constant",
            DefinitionKind::Let => "a `let` binding",
            DefinitionKind::Material => "a material",
            DefinitionKind::Function => "a function",
            DefinitionKind::Parameter => "a parameter",
            DefinitionKind::LoopVariable => "a loop variable",
        }
    }
}

/// What the compiler knows of a definition's value, as text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Shown {
    /// The first value (a loop's range, a material's properties one per line).
    pub text: String,
    /// How many times the definition ran with another value after the first (a `let` in a
    /// loop or a function); 0 when it had one value.
    pub others: u32,
}

/// Whether `word` can name a definition: a name as the grammar reads one (a letter or `_`,
/// then letters, digits and `_`), and not a keyword. The error says why not, in words.
pub fn check_name(word: &str) -> Result<(), String> {
    let mut chars = word.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if !first_ok || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "`{word}` is not a name: a name starts with a letter or `_` and goes on with letters, digits and `_`"
        ));
    }
    if crate::parser::is_keyword(word) {
        return Err(format!("`{word}` is a keyword of the language, not a name"));
    }
    Ok(())
}

/// A block that takes properties.
#[derive(Clone, Debug)]
pub struct BlockFacts {
    pub kind: BlockKind,
    /// From `{` to `}`.
    pub span: Span,
    /// The known properties written directly in it: (name, the name's span).
    pub properties: Vec<(&'static str, Span)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SymbolKind {
    Material,
    Light,
    Object,
    Function,
    Settings,
    Camera,
    Constant,
    Variable,
}

/// An entry of the outline.
#[derive(Clone, Debug)]
pub struct Symbol {
    pub kind: SymbolKind,
    /// `glass`, `sphere "ball"`, `light point`, ...
    pub name: String,
    /// The whole statement.
    pub span: Span,
    /// Its name, or its first word when it has none.
    pub selection: Span,
    /// Objects inside a union or group, statements inside a function.
    pub children: Vec<Symbol>,
}
