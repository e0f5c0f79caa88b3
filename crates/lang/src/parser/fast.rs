//! The fast path of parsing: a hand-written reader of grammar/scene.pest that builds the same
//! syntax tree as the pest parser, tried first on every file.
//!
//! Scenes written by scripts and exporters run to a million statements, and pest reads them
//! at about 2 MB/s (every rule it enters checks the native stack and a call budget). This
//! reader follows the grammar rule by rule: ordered choice with backtracking, whitespace and
//! comments skipped exactly where pest skips them (so every span matches to the byte, the
//! trailing whitespace pest keeps in some rules included), and the same tree-building
//! helpers. It gives up, returning `None`, on anything it does not read exactly as pest
//! would: any syntax error, nesting deeper than [`MAX_RECURSION`], any problem found while
//! building (a number too large, a bad escape, an expression past the depth limit). Pest then
//! parses the text from the start, so pest stays the grammar's reference and makes every
//! diagnostic. `tests` compares the two trees over every scene, docs example and generated
//! text.

use whitted_ir::Span;

use super::indexing_and_expression_bodies::index_expr;
use super::{combine, field_expr, hex_color, ExprPart, ParseContext};
use crate::ast::*;

/// How deep blocks and expressions may nest before this reader leaves the text to pest
/// (whose stack guard protects the deep cases); hand-written scenes stay far below it.
const MAX_RECURSION: usize = 48;

/// The grammar's `keyword` rule: words that are never names.
pub(crate) fn is_keyword(word: &str) -> bool {
    matches!(
        word,
        "import"
            | "const"
            | "let"
            | "fn"
            | "for"
            | "in"
            | "if"
            | "else"
            | "return"
            | "while"
            | "step"
            | "settings"
            | "camera"
            | "light"
            | "material"
            | "true"
            | "false"
            | "about"
            | "open"
    )
}

/// How deep in the final tree a node's subtree reaches, counted as the pest builder counts
/// (`ParseContext::expr` and `block`), so that the limit is enforced alike.
type Depth = usize;

/// One way to read a `primary`, tried in the grammar's order.
type Alternative<'t, 'c, 'a> = fn(&mut Reader<'t, 'c, 'a>) -> Option<(ExprKind, Depth)>;

/// Reads `text` as the `file` rule. `None` means "let pest do it"; the context is then as
/// it was before the call.
pub(super) fn parse_file(text: &str, cx: &mut ParseContext<'_>) -> Option<Vec<Item>> {
    let (interner_mark, functions_mark, errors_mark) =
        (cx.interner.mark(), cx.functions.len(), cx.errors.len());
    let base_depth = cx.depth;
    let mut reader = Reader {
        text,
        bytes: text.as_bytes(),
        pos: 0,
        cx,
        recursion: 0,
        pending: Vec::new(),
    };
    let result = reader.file();
    let cx = reader.cx;
    let clean = cx.errors.len() == errors_mark;
    match result {
        Some((items, depth)) if clean && base_depth + depth <= cx.max_expression_depth => {
            Some(items)
        }
        _ => {
            cx.interner.forget_after(interner_mark);
            cx.functions.truncate(functions_mark);
            cx.errors.truncate(errors_mark);
            None
        }
    }
}

/// Where to return to when an alternative fails.
#[derive(Clone, Copy)]
struct Checkpoint {
    pos: usize,
    interned: usize,
    functions: usize,
    errors: usize,
}

struct Reader<'t, 'c, 'a> {
    text: &'t str,
    bytes: &'t [u8],
    pos: usize,
    cx: &'c mut ParseContext<'a>,
    recursion: usize,
    /// The items of every block being read, innermost last: each block's list is moved out
    /// in one allocation of the exact size when the block ends (a million small blocks
    /// each growing its own vector spent a fifth of the time in reallocation).
    pending: Vec<Item>,
}

fn is_ident_char(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

impl<'t> Reader<'t, '_, '_> {
    // ---- positions and tokens ---------------------------------------------------------------

    fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            pos: self.pos,
            interned: self.cx.interner.mark(),
            functions: self.cx.functions.len(),
            errors: self.cx.errors.len(),
        }
    }

    fn restore(&mut self, checkpoint: Checkpoint) {
        self.pos = checkpoint.pos;
        self.cx.interner.forget_after(checkpoint.interned);
        self.cx.functions.truncate(checkpoint.functions);
        self.cx.errors.truncate(checkpoint.errors);
    }

    fn span(&self, start: usize, end: usize) -> Span {
        Span::new(self.cx.file, start, end)
    }

    fn byte(&self, at: usize) -> Option<u8> {
        self.bytes.get(at).copied()
    }

    /// Pest's implicit `WHITESPACE* ~ (COMMENT ~ WHITESPACE*)*`, run between the parts of
    /// every non-atomic rule.
    fn skip(&mut self) {
        loop {
            let rest = &self.bytes[self.pos..];
            match rest {
                [b' ' | b'\t' | b'\r' | b'\n', ..] => self.pos += 1,
                // U+FEFF, the byte-order mark, in UTF-8.
                [0xEF, 0xBB, 0xBF, ..] => self.pos += 3,
                [b'/', b'/', ..] => {
                    let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
                    self.pos += end;
                }
                [b'/', b'*', ..] => match rest[2..].windows(2).position(|w| w == b"*/") {
                    Some(at) => self.pos += 2 + at + 2,
                    // An unclosed comment is not a comment; the lexical pass reports it.
                    None => return,
                },
                _ => return,
            }
        }
    }

    /// Matches a literal string.
    fn eat(&mut self, literal: &str) -> bool {
        if self.bytes[self.pos..].starts_with(literal.as_bytes()) {
            self.pos += literal.len();
            true
        } else {
            false
        }
    }

    /// Matches a literal and returns its span.
    fn eat_span(&mut self, literal: &str) -> Option<Span> {
        let start = self.pos;
        self.eat(literal).then(|| self.span(start, self.pos))
    }

    /// The word (`(ASCII_ALPHA | "_") ~ ident_char*`) starting here, not consumed.
    fn word(&self) -> Option<&'t str> {
        let first = self.byte(self.pos)?;
        if !(first.is_ascii_alphabetic() || first == b'_') {
            return None;
        }
        let len = self.bytes[self.pos..]
            .iter()
            .position(|&b| !is_ident_char(b))
            .unwrap_or(self.bytes.len() - self.pos);
        self.text.get(self.pos..self.pos + len)
    }

    /// A `kw_*` rule: the keyword as a whole word.
    fn keyword(&mut self, keyword: &str) -> Option<Span> {
        if self.word()? != keyword {
            return None;
        }
        let start = self.pos;
        self.pos += keyword.len();
        Some(self.span(start, self.pos))
    }

    /// The `ident` rule: a word that is not a keyword, interned.
    fn ident(&mut self) -> Option<Ident> {
        let word = self.word()?;
        if is_keyword(word) {
            return None;
        }
        let start = self.pos;
        self.pos += word.len();
        let sym = self.cx.interner.intern(word);
        Some(Ident {
            sym,
            span: self.span(start, self.pos),
        })
    }

    fn name(&mut self) -> Option<Name> {
        Some(Name {
            ident: self.ident()?,
            res: Res::Unresolved,
        })
    }

    /// The `number` rule's end, if a number starts here.
    fn number_end(&self) -> Option<usize> {
        let digits = |at: usize| {
            self.bytes[at.min(self.bytes.len())..]
                .iter()
                .take_while(|b| b.is_ascii_digit())
                .count()
        };
        let mut at = self.pos;
        let whole = digits(at);
        if whole > 0 {
            at += whole;
            if self.byte(at) == Some(b'.') && digits(at + 1) > 0 {
                at += 1 + digits(at + 1);
            }
        } else if self.byte(at) == Some(b'.') && digits(at + 1) > 0 {
            at += 1 + digits(at + 1);
        } else {
            return None;
        }
        if matches!(self.byte(at), Some(b'e' | b'E')) {
            let sign = usize::from(matches!(self.byte(at + 1), Some(b'+' | b'-')));
            let exponent = digits(at + 1 + sign);
            if exponent > 0 {
                at += 1 + sign + exponent;
            }
        }
        match self.byte(at) {
            Some(b) if is_ident_char(b) => None,
            _ => Some(at),
        }
    }

    /// The `hex_color` rule's end, if one starts here.
    fn hex_end(&self) -> Option<usize> {
        if self.byte(self.pos)? != b'#' {
            return None;
        }
        let digits = self.bytes.get(self.pos + 1..self.pos + 7)?;
        if !digits.iter().all(u8::is_ascii_hexdigit) {
            return None;
        }
        let end = self.pos + 7;
        match self.byte(end) {
            Some(b) if is_ident_char(b) => None,
            _ => Some(end),
        }
    }

    /// The `string` rule: the raw text between the quotes and the span with them.
    fn string_raw(&mut self) -> Option<(&'t str, Span)> {
        let start = self.pos;
        if self.byte(start)? != b'"' {
            return None;
        }
        let mut at = start + 1;
        loop {
            match self.byte(at)? {
                b'"' => break,
                b'\n' => return None,
                b'\\' => {
                    // `"\\" ~ ANY`: the escaped character may be any character.
                    let next = self.text.get(at + 1..)?.chars().next()?;
                    at += 1 + next.len_utf8();
                }
                _ => at += 1,
            }
        }
        self.pos = at + 1;
        let raw = self.text.get(start + 1..at)?;
        Some((raw, self.span(start, self.pos)))
    }

    fn string(&mut self) -> Option<StrLit> {
        let (raw, span) = self.string_raw()?;
        Some(self.cx.string_lit(raw, span))
    }

    fn formatted_string(&mut self) -> Option<StrLit> {
        let (raw, span) = self.string_raw()?;
        Some(self.cx.formatted_lit(raw, span))
    }

    /// Runs `f` one nesting level deeper, or gives up past [`MAX_RECURSION`].
    fn nested<T>(&mut self, f: impl FnOnce(&mut Self) -> Option<T>) -> Option<T> {
        self.cx.steps += 1;
        if self.recursion >= MAX_RECURSION {
            return None;
        }
        self.recursion += 1;
        let result = f(self);
        self.recursion -= 1;
        result
    }

    // ---- files, blocks and items ------------------------------------------------------------

    fn file(&mut self) -> Option<(Vec<Item>, Depth)> {
        self.skip();
        let items = self.items()?;
        self.skip();
        (self.pos == self.bytes.len()).then_some(items)
    }

    /// `item*`. An item that fails ends the list, and the rule around it then needs `}` or
    /// the end of the text where that item started, which no item starts with: so a failed
    /// item fails the whole text.
    fn items(&mut self) -> Option<(Vec<Item>, Depth)> {
        let first = self.pending.len();
        let mut depth = 0;
        loop {
            let before = self.pos;
            if self.pending.len() > first {
                self.skip();
            }
            if matches!(self.byte(self.pos), None | Some(b'}')) {
                self.pos = before;
                // The file's own list is all of `pending`: taken whole, not copied.
                let items = if first == 0 {
                    std::mem::take(&mut self.pending)
                } else {
                    self.pending.drain(first..).collect()
                };
                return Some((items, depth));
            }
            let Some((item, item_depth)) = self.item() else {
                self.pending.truncate(first);
                return None;
            };
            depth = depth.max(item_depth);
            self.pending.push(item);
        }
    }

    /// `block?`: a block if one follows, else nothing consumed.
    fn optional_block(&mut self) -> Option<(Block, Depth)> {
        let checkpoint = self.checkpoint();
        let found = self.block();
        if found.is_none() {
            self.restore(checkpoint);
        }
        found
    }

    /// `(kw_KEYWORD ~ expr)?`: the expression after the keyword if both follow, else nothing
    /// consumed.
    fn optional_keyword_expr(&mut self, keyword: &str) -> Option<(Expr, Depth)> {
        let checkpoint = self.checkpoint();
        self.keyword(keyword)?;
        self.skip();
        let found = self.expr(false);
        if found.is_none() {
            self.restore(checkpoint);
        }
        found
    }

    fn block(&mut self) -> Option<(Block, Depth)> {
        self.nested(|r| {
            let start = r.pos;
            if !r.eat("{") {
                return None;
            }
            r.skip();
            let (items, depth) = r.items()?;
            r.skip();
            if !r.eat("}") {
                return None;
            }
            // A block and the item inside it are two levels of every recursive pass.
            let block = Block {
                items,
                span: r.span(start, r.pos),
            };
            Some((block, 2 + depth))
        })
    }

    fn item(&mut self) -> Option<(Item, Depth)> {
        self.cx.steps += 1;
        let start = self.pos;
        let word = self.word()?;
        let (kind, depth) = match word {
            "import" => self.import_stmt()?,
            "const" | "let" => self.binding_stmt(word == "const")?,
            "fn" => self.fn_stmt()?,
            "for" => self.for_stmt()?,
            "while" => self.while_stmt()?,
            "if" => return self.if_stmt(),
            "return" => self.return_stmt()?,
            "settings" => {
                self.keyword("settings")?;
                self.skip();
                let (block, depth) = self.block()?;
                (ItemKind::Settings(block), depth)
            }
            "camera" => self.camera_stmt()?,
            "light" => self.light_stmt()?,
            "material" => {
                let checkpoint = self.checkpoint();
                match self.material_stmt(start) {
                    Some(found) => found,
                    None => {
                        self.restore(checkpoint);
                        self.material_prop(start)?
                    }
                }
            }
            "open" => {
                // `flag`: the keyword is the property's name.
                let span = self.keyword("open")?;
                let name = Ident {
                    sym: self.cx.interner.intern("open"),
                    span,
                };
                (
                    ItemKind::Property(property(
                        name,
                        PropertyValues::Many(Vec::new()),
                        None,
                        None,
                    )),
                    0,
                )
            }
            _ if is_keyword(word) => return None,
            _ => self.ident_item()?,
        };
        let item = Item {
            kind,
            span: self.span(start, self.pos),
        };
        Some((item, depth))
    }

    /// `call_stmt | assign_stmt | object_stmt | property`, in the grammar's order. Each
    /// alternative is tried only where its first tokens are present, which it needs to match.
    fn ident_item(&mut self) -> Option<(ItemKind, Depth)> {
        let word_len = self.word()?.len();
        let after_word = self.pos + word_len;
        if self.byte(after_word) == Some(b'(') {
            // `f(` is a call; if its arguments fail, so would every other reading.
            return self.call_stmt();
        }
        let checkpoint = self.checkpoint();
        let next = {
            self.pos = after_word;
            self.skip();
            let next = self.byte(self.pos);
            self.pos = checkpoint.pos;
            next
        };
        if next == Some(b'=') {
            if let Some(found) = self.assign_stmt() {
                return Some(found);
            }
            self.restore(checkpoint);
        }
        if matches!(next, Some(b'"' | b'{')) {
            if let Some(found) = self.object_stmt() {
                return Some(found);
            }
            self.restore(checkpoint);
        }
        self.property_item()
    }

    fn import_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        self.keyword("import")?;
        self.skip();
        let path = self.string()?;
        Some((
            ItemKind::Import {
                path: Box::new(path),
                file: None,
            },
            0,
        ))
    }

    fn binding_stmt(&mut self, constant: bool) -> Option<(ItemKind, Depth)> {
        self.keyword(if constant { "const" } else { "let" })?;
        self.skip();
        let name = self.ident()?;
        self.skip();
        if !self.eat("=") {
            return None;
        }
        self.skip();
        let (value, depth) = self.expr(false)?;
        self.skip();
        if !self.eat(";") {
            return None;
        }
        let binding = Binding {
            name,
            value,
            slot: Slot::None,
        };
        let kind = if constant {
            ItemKind::Const(binding)
        } else {
            ItemKind::Let(binding)
        };
        Some((kind, depth))
    }

    fn fn_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        self.keyword("fn")?;
        self.skip();
        let name = self.ident()?;
        self.skip();
        let params = self.params()?;
        self.skip();
        let (body, depth) = if self.byte(self.pos) == Some(b'=') {
            self.fn_expr_body()?
        } else {
            self.block()?
        };
        self.cx.functions.push(FnDef {
            name,
            params,
            body,
            frame_size: 0,
        });
        Some((ItemKind::Fn(self.cx.functions.len() - 1), depth))
    }

    /// `params = { "(" ~ (ident ~ ("," ~ ident)* ~ ","?)? ~ ")" }`.
    fn params(&mut self) -> Option<Vec<Ident>> {
        if !self.eat("(") {
            return None;
        }
        self.skip();
        let items = self.comma_list(|r| r.ident().map(|ident| (ident, 0)))?;
        self.skip();
        self.eat(")")
            .then(|| items.into_iter().map(|(i, _)| i).collect())
    }

    /// `= expr ;` after a function's parameters: a body of one `return expr;`.
    fn fn_expr_body(&mut self) -> Option<(Block, Depth)> {
        let start = self.pos;
        if !self.eat("=") {
            return None;
        }
        self.skip();
        let (value, depth) = self.expr(false)?;
        self.skip();
        if !self.eat(";") {
            return None;
        }
        let item = Item {
            span: value.span,
            kind: ItemKind::Return(value),
        };
        let block = Block {
            items: vec![item],
            span: self.span(start, self.pos),
        };
        Some((block, 2 + depth))
    }

    fn for_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        self.keyword("for")?;
        self.skip();
        let var = self.ident()?;
        self.skip();
        self.keyword("in")?;
        self.skip();
        let (start, start_depth) = self.expr(false)?;
        self.skip();
        let inclusive = if self.eat("..=") {
            true
        } else if self.eat("..") {
            false
        } else {
            return None;
        };
        self.skip();
        let (end, end_depth) = self.expr(false)?;
        self.skip();
        let mut depth = start_depth.max(end_depth);
        let step = self
            .optional_keyword_expr("step")
            .map(|(value, step_depth)| {
                depth = depth.max(step_depth);
                value
            });
        self.skip();
        let (body, body_depth) = self.block()?;
        let kind = ItemKind::For {
            var,
            slot: Slot::None,
            start: Box::new(start),
            end: Box::new(end),
            inclusive,
            step: step.map(Box::new),
            body,
        };
        Some((kind, depth.max(body_depth)))
    }

    fn while_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        self.keyword("while")?;
        self.skip();
        let (condition, condition_depth) = self.expr(false)?;
        self.skip();
        let (body, body_depth) = self.block()?;
        let kind = ItemKind::While {
            condition: Box::new(condition),
            body,
        };
        Some((kind, condition_depth.max(body_depth)))
    }

    /// `if_stmt`, a whole item (it is also the `else if` of another).
    fn if_stmt(&mut self) -> Option<(Item, Depth)> {
        let start = self.pos;
        self.keyword("if")?;
        self.skip();
        let (condition, condition_depth) = self.expr(false)?;
        self.skip();
        let (then, then_depth) = self.block()?;
        let mut depth = condition_depth.max(then_depth);
        self.skip();
        let checkpoint = self.checkpoint();
        let mut otherwise = None;
        if self.keyword("else").is_some() {
            self.skip();
            let branch = if self.word() == Some("if") {
                self.if_stmt()
                    .map(|(item, d)| (Else::If(Box::new(item)), d))
            } else {
                self.block().map(|(block, d)| (Else::Block(block), d))
            };
            match branch {
                Some((branch, branch_depth)) => {
                    otherwise = Some(branch);
                    depth = depth.max(branch_depth);
                }
                None => self.restore(checkpoint),
            }
        }
        let item = Item {
            kind: ItemKind::If {
                condition: Box::new(condition),
                then,
                otherwise: otherwise.map(Box::new),
            },
            span: self.span(start, self.pos),
        };
        Some((item, depth))
    }

    fn return_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        self.keyword("return")?;
        self.skip();
        let (value, depth) = self.expr(false)?;
        self.skip();
        self.eat(";").then_some((ItemKind::Return(value), depth))
    }

    fn camera_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        self.keyword("camera")?;
        self.skip();
        let kind = self.ident()?;
        self.skip();
        let (body, depth) = self.block()?;
        let item = ItemKind::Camera {
            kind,
            tag: None,
            body,
        };
        Some((item, depth))
    }

    fn light_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        self.keyword("light")?;
        self.skip();
        let kind = self.ident()?;
        self.skip();
        let (name, body, depth) = self.optional_name_and_block()?;
        let item = ItemKind::Light {
            kind,
            tag: None,
            name: name.map(Box::new),
            body,
        };
        Some((item, depth))
    }

    /// `string? ~ block`.
    fn optional_name_and_block(&mut self) -> Option<(Option<StrLit>, Block, Depth)> {
        let checkpoint = self.checkpoint();
        let name = self.formatted_string();
        if name.is_none() {
            self.restore(checkpoint);
        }
        self.skip();
        let (body, depth) = self.block()?;
        Some((name, body, depth))
    }

    /// `material name (: parent)? { ... }`, a named material.
    fn material_stmt(&mut self, start: usize) -> Option<(ItemKind, Depth)> {
        self.keyword("material")?;
        self.skip();
        let name = self.ident()?;
        self.skip();
        let parent = self.optional_parent();
        self.skip();
        let (block, depth) = self.block()?;
        let header_end = parent.as_ref().map_or(name.span.end, |p| p.ident.span.end);
        let body = MaterialBody {
            header: self.span(start, header_end as usize),
            parent,
            block,
        };
        let kind = ItemKind::Material {
            name,
            slot: Slot::None,
            body: Box::new(body),
        };
        Some((kind, depth))
    }

    /// `(":" ~ ident)?`.
    fn optional_parent(&mut self) -> Option<Name> {
        let checkpoint = self.checkpoint();
        if !self.eat(":") {
            return None;
        }
        self.skip();
        let parent = self.name();
        if parent.is_none() {
            self.restore(checkpoint);
        }
        parent
    }

    /// `material_body = { (":" ~ ident)? ~ block }`; `keyword` is the `material` before it.
    fn material_body(&mut self, keyword: Span) -> Option<(MaterialBody, Depth)> {
        let parent = self.optional_parent();
        self.skip();
        let (block, depth) = self.block()?;
        Some((
            self.cx.material_body_of(parent, Some(block), keyword),
            depth,
        ))
    }

    /// `material glass`, `material { ... }` or `material : glass { ... }` inside a block.
    fn material_prop(&mut self, start: usize) -> Option<(ItemKind, Depth)> {
        let keyword = self.keyword("material")?;
        let name = Ident {
            sym: self.cx.interner.intern("material"),
            span: keyword,
        };
        self.skip();
        let checkpoint = self.checkpoint();
        let (value, depth) = match self.material_body(self.span(start, keyword.end as usize)) {
            Some((body, depth)) => {
                let value = Expr {
                    kind: ExprKind::Material(Box::new(body)),
                    span: self.span(start, self.pos),
                };
                (value, depth)
            }
            None => {
                self.restore(checkpoint);
                self.expr(false)?
            }
        };
        let kind = ItemKind::Property(property(name, PropertyValues::One(value), None, None));
        Some((kind, depth))
    }

    fn call_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        let (call, mut depth) = self.call()?;
        self.skip();
        let modifiers = self.optional_block().map(|(block, block_depth)| {
            depth = depth.max(block_depth);
            block
        });
        Some((
            ItemKind::Call {
                call: Box::new(call),
                modifiers,
            },
            depth,
        ))
    }

    /// `ident ~ "=" ~ !"=" ~ expr ~ ";"`.
    fn assign_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        let ident = self.ident()?;
        self.skip();
        if !self.eat("=") {
            return None;
        }
        self.skip();
        if self.byte(self.pos) == Some(b'=') {
            return None;
        }
        let (value, depth) = self.expr(false)?;
        self.skip();
        if !self.eat(";") {
            return None;
        }
        let target = Name {
            ident,
            res: Res::Unresolved,
        };
        Some((ItemKind::Assign { target, value }, depth))
    }

    fn object_stmt(&mut self) -> Option<(ItemKind, Depth)> {
        let kind = self.ident()?;
        self.skip();
        let (name, body, depth) = self.optional_name_and_block()?;
        let item = ItemKind::Object {
            kind,
            tag: None,
            name: name.map(Box::new),
            body,
        };
        Some((item, depth))
    }

    /// `ident ~ expr ~ ("," ~ expr)* ~ (kw_about ~ expr)? ~ block?`.
    fn property_item(&mut self) -> Option<(ItemKind, Depth)> {
        let name = self.ident()?;
        self.skip();
        let (first, mut depth) = self.expr(false)?;
        let mut values = PropertyValues::One(first);
        self.skip();
        loop {
            let checkpoint = self.checkpoint();
            if values.len() > 1 {
                self.skip();
            }
            let next = if self.eat(",") {
                self.skip();
                self.expr(false)
            } else {
                None
            };
            match next {
                Some((value, value_depth)) => {
                    values = match values {
                        PropertyValues::One(first) => PropertyValues::Many(vec![first, value]),
                        PropertyValues::Many(mut list) => {
                            list.push(value);
                            PropertyValues::Many(list)
                        }
                    };
                    depth = depth.max(value_depth);
                }
                None => {
                    self.restore(checkpoint);
                    break;
                }
            }
        }
        self.skip();
        let about = self
            .optional_keyword_expr("about")
            .map(|(value, about_depth)| {
                depth = depth.max(about_depth);
                value
            });
        self.skip();
        let block = self.optional_block().map(|(block, block_depth)| {
            depth = depth.max(block_depth);
            block
        });
        let kind = ItemKind::Property(property(name, values, about, block));
        Some((kind, depth))
    }

    // ---- expressions ------------------------------------------------------------------------

    /// `(x ~ ("," ~ x)* ~ ","?)?`, the inside of arguments, arrays and parameters.
    fn comma_list<T>(
        &mut self,
        mut element: impl FnMut(&mut Self) -> Option<(T, Depth)>,
    ) -> Option<Vec<(T, Depth)>> {
        let mut list = Vec::new();
        let checkpoint = self.checkpoint();
        let Some(first) = element(self) else {
            self.restore(checkpoint);
            return Some(list);
        };
        list.push(first);
        self.skip();
        loop {
            let checkpoint = self.checkpoint();
            if list.len() > 1 {
                self.skip();
            }
            let next = if self.eat(",") {
                self.skip();
                element(self)
            } else {
                None
            };
            match next {
                Some(found) => list.push(found),
                None => {
                    self.restore(checkpoint);
                    break;
                }
            }
        }
        self.skip();
        self.eat(",");
        Some(list)
    }

    /// `expr` (or `arith`, inside `<x, y, z>`, where `>` closes the vector).
    fn expr(&mut self, arith: bool) -> Option<(Expr, Depth)> {
        self.nested(|r| {
            let start = r.pos;
            let mut parts = Vec::new();
            // The pest builder counts one level for the expression, one per operator and
            // one per operand and each of its fields and indexes.
            let mut added = 1;
            added += r.prefixes(&mut parts);
            r.skip();
            let (operand, count, mut below) = r.postfix()?;
            added += count;
            // Most expressions are one operand: it is the tree, with no list to combine.
            let mut lone = Some(operand);
            if !parts.is_empty() {
                parts.extend(lone.take().map(ExprPart::Operand));
            }
            r.skip();
            let mut first = true;
            loop {
                let checkpoint = r.checkpoint();
                if !first {
                    r.skip();
                }
                let Some((op, op_span)) = r.infix(arith) else {
                    r.restore(checkpoint);
                    break;
                };
                parts.extend(lone.take().map(ExprPart::Operand));
                let parts_before = parts.len();
                parts.push(ExprPart::Infix(op, op_span));
                match r.operand_after_infix(&mut parts) {
                    Some((levels, operand_depth)) => {
                        added += 1 + levels;
                        below = below.max(operand_depth);
                        first = false;
                    }
                    None => {
                        r.restore(checkpoint);
                        parts.truncate(parts_before);
                        break;
                    }
                }
            }
            let tree = match lone {
                Some(operand) => operand,
                None => combine(parts, r.span(start, r.pos)),
            };
            Some((tree, added + below))
        })
    }

    /// `prefix*`; returns how many.
    fn prefixes(&mut self, parts: &mut Vec<ExprPart>) -> usize {
        let mut count = 0;
        loop {
            let before = self.pos;
            if count > 0 {
                self.skip();
            }
            let at = self.pos;
            let op = match self.byte(at) {
                Some(b'-') => UnaryOp::Neg,
                Some(b'!') => UnaryOp::Not,
                _ => {
                    self.pos = before;
                    return count;
                }
            };
            self.pos += 1;
            parts.push(ExprPart::Prefix(op, self.span(at, self.pos)));
            count += 1;
        }
    }

    /// `prefix* ~ postfix` after an infix operator; returns the levels they add and the
    /// operand's depth.
    fn operand_after_infix(&mut self, parts: &mut Vec<ExprPart>) -> Option<(usize, Depth)> {
        self.skip();
        let prefixes = self.prefixes(parts);
        self.skip();
        let (operand, count, depth) = self.postfix()?;
        parts.push(ExprPart::Operand(operand));
        Some((prefixes + count, depth))
    }

    /// The `infix` rule (or `arith_infix`), in the grammar's order.
    fn infix(&mut self, arith: bool) -> Option<(BinaryOp, Span)> {
        const COMPARISONS: [(&str, BinaryOp); 8] = [
            ("||", BinaryOp::Or),
            ("&&", BinaryOp::And),
            ("==", BinaryOp::Eq),
            ("!=", BinaryOp::Ne),
            ("<=", BinaryOp::Le),
            (">=", BinaryOp::Ge),
            ("<", BinaryOp::Lt),
            (">", BinaryOp::Gt),
        ];
        const ARITHMETIC: [(&str, BinaryOp); 5] = [
            ("+", BinaryOp::Add),
            ("-", BinaryOp::Sub),
            ("*", BinaryOp::Mul),
            ("/", BinaryOp::Div),
            ("%", BinaryOp::Rem),
        ];
        // Most operands are followed by `,`, `>` or `}`: one look at the next byte rules out
        // every operator but `>` before trying them one by one.
        if !matches!(
            self.byte(self.pos),
            Some(b'|' | b'&' | b'=' | b'!' | b'<' | b'>' | b'+' | b'-' | b'*' | b'/' | b'%')
        ) {
            return None;
        }
        let comparisons: &[(&str, BinaryOp)] = if arith { &[] } else { &COMPARISONS };
        for &(literal, op) in comparisons.iter().chain(ARITHMETIC.iter()) {
            if let Some(span) = self.eat_span(literal) {
                return Some((op, span));
            }
        }
        None
    }

    /// `primary ~ (field | index)*`; returns the operand, how many parts it has (the
    /// primary and each field and index) and its depth.
    fn postfix(&mut self) -> Option<(Expr, usize, Depth)> {
        let (mut operand, mut depth) = self.primary()?;
        let mut count = 1;
        self.skip();
        loop {
            let checkpoint = self.checkpoint();
            if count > 1 {
                self.skip();
            }
            if let Some((name, field_span)) = self.field() {
                operand = field_expr(operand, name, field_span);
                count += 1;
                continue;
            }
            if let Some((index, index_span, index_depth)) = self.index() {
                operand = index_expr(operand, index, index_span);
                depth = depth.max(index_depth);
                count += 1;
                continue;
            }
            self.restore(checkpoint);
            return Some((operand, count, depth));
        }
    }

    /// `field = ${ "." ~ ident }`.
    fn field(&mut self) -> Option<(Ident, Span)> {
        let start = self.pos;
        if !self.eat(".") {
            return None;
        }
        match self.ident() {
            Some(name) => Some((name, self.span(start, self.pos))),
            None => {
                self.pos = start;
                None
            }
        }
    }

    /// `index = !{ "[" ~ expr ~ "]" }`.
    fn index(&mut self) -> Option<(Expr, Span, Depth)> {
        let checkpoint = self.checkpoint();
        let found = (|| {
            let start = self.pos;
            if !self.eat("[") {
                return None;
            }
            self.skip();
            let (index, depth) = self.expr(false)?;
            self.skip();
            self.eat("]")
                .then(|| (index, self.span(start, self.pos), depth))
        })();
        if found.is_none() {
            self.restore(checkpoint);
        }
        found
    }

    /// The `primary` rule: its alternatives in the grammar's order.
    fn primary(&mut self) -> Option<(Expr, Depth)> {
        self.cx.steps += 1;
        let start = self.pos;
        let leaf = |r: &Self, kind| Expr {
            kind,
            span: r.span(start, r.pos),
        };
        if let Some(end) = self.number_end() {
            let text = self.text.get(start..end)?;
            self.pos = end;
            return Some((self.cx.number(text, self.span(start, end)), 0));
        }
        if let Some(end) = self.hex_end() {
            let text = self.text.get(start..end)?;
            self.pos = end;
            return Some((hex_color(text, self.span(start, end)), 0));
        }
        // Each remaining alternative needs its own first character, so only the ones that
        // can match here are tried (in the grammar's order).
        let alternatives: &[Alternative<'t, '_, '_>] = match self.byte(start) {
            Some(b'<') => &[Self::vector],
            Some(b'[') => &[Self::array],
            Some(b'"') => &[Self::string_value],
            Some(b'(') => return self.paren(),
            Some(b) if b.is_ascii_alphabetic() || b == b'_' => &[
                Self::boolean,
                Self::material_literal,
                Self::call_value,
                Self::name_value,
            ],
            _ => return None,
        };
        for alternative in alternatives {
            let checkpoint = self.checkpoint();
            if let Some((kind, depth)) = alternative(self) {
                return Some((leaf(self, kind), depth));
            }
            self.restore(checkpoint);
        }
        None
    }

    /// `kw_true | kw_false`.
    fn boolean(&mut self) -> Option<(ExprKind, Depth)> {
        match self.word()? {
            "true" => self.keyword("true").map(|_| (ExprKind::Bool(true), 0)),
            "false" => self.keyword("false").map(|_| (ExprKind::Bool(false), 0)),
            _ => None,
        }
    }

    /// `vector = { "<" ~ arith ~ "," ~ arith ~ "," ~ arith ~ ">" }`.
    fn vector(&mut self) -> Option<(ExprKind, Depth)> {
        if !self.eat("<") {
            return None;
        }
        self.skip();
        let (x, dx) = self.expr(true)?;
        self.skip();
        if !self.eat(",") {
            return None;
        }
        self.skip();
        let (y, dy) = self.expr(true)?;
        self.skip();
        if !self.eat(",") {
            return None;
        }
        self.skip();
        let (z, dz) = self.expr(true)?;
        self.skip();
        if !self.eat(">") {
            return None;
        }
        Some((ExprKind::Vector(Box::new([x, y, z])), dx.max(dy).max(dz)))
    }

    /// `array = !{ "[" ~ (expr ~ ("," ~ expr)* ~ ","?)? ~ "]" }`.
    fn array(&mut self) -> Option<(ExprKind, Depth)> {
        if !self.eat("[") {
            return None;
        }
        self.skip();
        let list = self.comma_list(|r| r.expr(false))?;
        self.skip();
        if !self.eat("]") {
            return None;
        }
        let depth = list.iter().map(|(_, d)| *d).max().unwrap_or(0);
        let items = list.into_iter().map(|(e, _)| e).collect();
        Some((ExprKind::Array(items), depth))
    }

    fn string_value(&mut self) -> Option<(ExprKind, Depth)> {
        let lit = self.formatted_string()?;
        Some((ExprKind::Str(Box::new(lit)), 0))
    }

    /// `material_literal = { kw_material ~ material_body }`.
    fn material_literal(&mut self) -> Option<(ExprKind, Depth)> {
        let keyword = self.keyword("material")?;
        self.skip();
        let (body, depth) = self.material_body(keyword)?;
        Some((ExprKind::Material(Box::new(body)), depth))
    }

    fn call_value(&mut self) -> Option<(ExprKind, Depth)> {
        let (call, depth) = self.call()?;
        Some((ExprKind::Call(Box::new(call)), depth))
    }

    fn name_value(&mut self) -> Option<(ExprKind, Depth)> {
        Some((ExprKind::Name(self.name()?), 0))
    }

    /// `call = ${ ident ~ args }`, with `args = !{ "(" ~ (expr ~ ("," ~ expr)* ~ ","?)? ~ ")" }`:
    /// no space between the name and its `(`.
    fn call(&mut self) -> Option<(Call, Depth)> {
        let start = self.pos;
        let callee = self.ident()?;
        if !self.eat("(") {
            return None;
        }
        self.skip();
        let list = self.comma_list(|r| r.expr(false))?;
        self.skip();
        if !self.eat(")") {
            return None;
        }
        let depth = list.iter().map(|(_, d)| *d).max().unwrap_or(0);
        let call = Call {
            callee,
            args: list.into_iter().map(|(e, _)| e).collect(),
            target: CallTarget::Unresolved,
            span: self.span(start, self.pos),
        };
        Some((call, depth))
    }

    /// `paren = { "(" ~ expr ~ ")" }`: the inner expression with the brackets' span.
    fn paren(&mut self) -> Option<(Expr, Depth)> {
        let start = self.pos;
        if !self.eat("(") {
            return None;
        }
        self.skip();
        let (inner, depth) = self.expr(false)?;
        self.skip();
        if !self.eat(")") {
            return None;
        }
        let expr = Expr {
            kind: inner.kind,
            span: self.span(start, self.pos),
        };
        Some((expr, depth))
    }
}

fn property(
    name: Ident,
    values: PropertyValues,
    about: Option<Expr>,
    block: Option<Block>,
) -> Property {
    Property {
        name,
        values,
        about: about.map(Box::new),
        block: block.map(Box::new),
        prop: None,
    }
}

#[cfg(test)]
mod tests;
