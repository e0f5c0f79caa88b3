//! The editor's index, read off the resolved syntax tree of every file: the blocks that take
//! properties with what is written in them, the resolver's links from names to definitions,
//! the outline, objects' names and the file strings of imports and meshes.

use whitted_ir::Span;

use super::{BlockFacts, BlockKind, Definition, DefinitionKind, Index, Shown, Symbol, SymbolKind};
use crate::ast::{
    Block, Else, Expr, ExprKind, Item, ItemKind, MaterialBody, Program, StrLit, StrPart,
};
use crate::intern::Interner;
use crate::resolve::{DefKind, Resolution};
use crate::schema::Context;

pub(crate) fn build(program: &Program, interner: &Interner, resolution: &Resolution) -> Index {
    let mut walker = Walker {
        program,
        interner,
        blocks: Vec::new(),
        signatures: std::collections::HashMap::new(),
        object_names: Vec::new(),
        paths: Vec::new(),
    };
    let mut symbols = Vec::new();
    for file in &program.files {
        for item in &file.items {
            walker.item(item, &mut symbols);
        }
    }
    let definitions = resolution
        .definitions
        .iter()
        .map(|&(span, kind)| Definition {
            span,
            kind: match kind {
                DefKind::Const => DefinitionKind::Constant,
                DefKind::Let => DefinitionKind::Let,
                DefKind::Material => DefinitionKind::Material,
                DefKind::Function => DefinitionKind::Function,
                DefKind::Parameter => DefinitionKind::Parameter,
                DefKind::LoopVariable => DefinitionKind::LoopVariable,
            },
        })
        .collect();
    Index {
        blocks: walker.blocks,
        links: resolution.links.clone(),
        symbols,
        definitions,
        shown: walker.signatures,
        object_names: walker.object_names,
        paths: walker.paths,
    }
}

struct Walker<'a> {
    program: &'a Program,
    interner: &'a Interner,
    blocks: Vec<BlockFacts>,
    /// Each function's signature, by its name's span.
    signatures: std::collections::HashMap<Span, Shown>,
    object_names: Vec<(Span, String)>,
    paths: Vec<(Span, String)>,
}

/// The text of a string literal that is plain text: no `{name}` holes and no escapes (each
/// escape is two bytes of the literal for one of its value), so the name is exactly the
/// bytes between its quotes and an editor can replace them.
fn plain(literal: &StrLit) -> Option<&str> {
    let holes = literal
        .parts
        .iter()
        .any(|part| matches!(part, StrPart::Hole(_)));
    let exact = (literal.span.end - literal.span.start) as usize == literal.value.len() + 2;
    (!holes && exact && !literal.value.is_empty()).then_some(literal.value.as_str())
}

impl Walker<'_> {
    /// A block of statements: its symbols go to `symbols`.
    fn statements(&mut self, block: &Block, symbols: &mut Vec<Symbol>) {
        for item in &block.items {
            self.item(item, symbols);
        }
    }

    /// A block of properties (or of objects, in a union): its facts, and its objects'
    /// symbols in `symbols`.
    fn properties(&mut self, block: &Block, context: Context, symbols: &mut Vec<Symbol>) {
        let at = self.blocks.len();
        self.blocks.push(BlockFacts {
            kind: BlockKind(context),
            span: block.span,
            properties: Vec::new(),
        });
        for item in &block.items {
            if let ItemKind::Property(property) = &item.kind {
                if let Some(prop) = property.prop {
                    self.blocks[at]
                        .properties
                        .push((prop.name(), property.name.span));
                }
            }
            self.item(item, symbols);
        }
    }

    fn material(&mut self, body: &MaterialBody) {
        self.properties(&body.block, Context::Material, &mut Vec::new());
    }

    fn item(&mut self, item: &Item, symbols: &mut Vec<Symbol>) {
        let symbol = |kind, name: String, selection: Span, children| Symbol {
            kind,
            name,
            span: item.span,
            selection,
            children,
        };
        match &item.kind {
            ItemKind::Import { path, .. } => {
                if let Some(text) = plain(path) {
                    self.paths.push((path.span, text.to_string()));
                }
            }
            ItemKind::Return(_) | ItemKind::Assign { .. } => {}
            ItemKind::Const(binding) | ItemKind::Let(binding) => {
                let kind = if matches!(item.kind, ItemKind::Const(_)) {
                    SymbolKind::Constant
                } else {
                    SymbolKind::Variable
                };
                let name = self.interner.name(binding.name.sym).to_string();
                symbols.push(symbol(kind, name, binding.name.span, Vec::new()));
                self.expr(&binding.value);
            }
            ItemKind::Fn(id) => {
                if let Some(function) = self.program.functions.get(*id) {
                    let mut children = Vec::new();
                    self.statements(&function.body, &mut children);
                    let name = self.interner.name(function.name.sym).to_string();
                    let params: Vec<&str> = function
                        .params
                        .iter()
                        .map(|p| self.interner.name(p.sym))
                        .collect();
                    self.signatures.insert(
                        function.name.span,
                        Shown {
                            text: format!("fn {name}({})", params.join(", ")),
                            others: 0,
                        },
                    );
                    symbols.push(symbol(
                        SymbolKind::Function,
                        name,
                        function.name.span,
                        children,
                    ));
                }
            }
            ItemKind::For { body, .. } | ItemKind::While { body, .. } => {
                self.statements(body, symbols);
            }
            ItemKind::If {
                then, otherwise, ..
            } => {
                self.statements(then, symbols);
                match otherwise.as_deref() {
                    Some(Else::Block(block)) => self.statements(block, symbols),
                    Some(Else::If(item)) => self.item(item, symbols),
                    None => {}
                }
            }
            ItemKind::Settings(body) => {
                self.properties(body, Context::Settings, &mut Vec::new());
                let keyword = Span::new(
                    item.span.file,
                    item.span.start as usize,
                    item.span.start as usize + "settings".len(),
                );
                symbols.push(symbol(
                    SymbolKind::Settings,
                    "settings".into(),
                    keyword,
                    Vec::new(),
                ));
            }
            ItemKind::Camera { kind, tag, body } => {
                self.properties(
                    body,
                    tag.map_or(Context::Unknown, Context::Camera),
                    &mut Vec::new(),
                );
                let name = format!("camera {}", self.interner.name(kind.sym));
                symbols.push(symbol(SymbolKind::Camera, name, kind.span, Vec::new()));
            }
            ItemKind::Light {
                kind,
                tag,
                name,
                body,
            } => {
                self.properties(
                    body,
                    tag.map_or(Context::Unknown, Context::Light),
                    &mut Vec::new(),
                );
                let mut text = format!("light {}", self.interner.name(kind.sym));
                if let Some(name) = name {
                    text.push_str(&format!(" \"{}\"", name.value));
                }
                symbols.push(symbol(SymbolKind::Light, text, kind.span, Vec::new()));
            }
            ItemKind::Material { name, body, .. } => {
                self.material(body);
                let text = self.interner.name(name.sym).to_string();
                symbols.push(symbol(SymbolKind::Material, text, name.span, Vec::new()));
            }
            ItemKind::Object {
                kind,
                tag,
                name,
                body,
            } => {
                let mut children = Vec::new();
                self.properties(
                    body,
                    tag.map_or(Context::Unknown, Context::Object),
                    &mut children,
                );
                let mut text = self.interner.name(kind.sym).to_string();
                if let Some(name) = name {
                    text.push_str(&format!(" \"{}\"", name.value));
                    if let Some(plain) = plain(name) {
                        self.object_names.push((name.span, plain.to_string()));
                    }
                }
                symbols.push(symbol(SymbolKind::Object, text, kind.span, children));
            }
            ItemKind::Call { call, modifiers } => {
                for arg in &call.args {
                    self.expr(arg);
                }
                if let Some(block) = modifiers {
                    self.properties(block, Context::Modifiers, &mut Vec::new());
                }
            }
            ItemKind::Property(property) => {
                if property.prop.is_some_and(|p| p.name() == "file") {
                    if let [Expr {
                        kind: ExprKind::Str(literal),
                        ..
                    }] = property.values.as_slice()
                    {
                        if let Some(text) = plain(literal) {
                            self.paths.push((literal.span, text.to_string()));
                        }
                    }
                }
                for value in &property.values {
                    self.expr(value);
                }
                if let Some(block) = &property.block {
                    self.properties(block, Context::PatternTransform, &mut Vec::new());
                }
            }
        }
    }

    /// Material literals inside expressions (`material { ... }` in an object) are blocks too.
    fn expr(&mut self, expr: &Expr) {
        match &expr.kind {
            ExprKind::Material(body) => self.material(body),
            ExprKind::Vector(parts) => parts.iter().for_each(|e| self.expr(e)),
            ExprKind::Unary(_, inner) => self.expr(inner),
            ExprKind::Binary { lhs, rhs, .. } => {
                self.expr(lhs);
                self.expr(rhs);
            }
            ExprKind::Field { base, .. } => self.expr(base),
            ExprKind::Call(call) => call.args.iter().for_each(|e| self.expr(e)),
            ExprKind::Array(items) => items.iter().for_each(|e| self.expr(e)),
            ExprKind::Index { base, index } => {
                self.expr(base);
                self.expr(index);
            }
            ExprKind::Number(_)
            | ExprKind::Bool(_)
            | ExprKind::Color(_)
            | ExprKind::Name(_)
            | ExprKind::Str(_) => {}
        }
    }
}
