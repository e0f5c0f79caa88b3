//! Text to syntax tree: the pest parser derived from grammar/scene.pest, and the conversion of
//! its pairs into [`crate::ast`] nodes with spans.
//!
//! Expressions arrive from pest as flat lists of operands and operators; precedence is applied
//! here with an explicit operator stack, so no input can make this code recurse deeper than
//! the brackets it contains (and those are limited by [`crate::lexical`]).

use pest::iterators::Pair;
use pest::Parser as _;
use whitted_ir::{DVec3, Diagnostic, FileId, Span};

use crate::ast::*;
use crate::builtins::srgb_to_linear;
use crate::intern::Interner;
use crate::lexical;
use crate::syntax_error;

mod fast;
pub(crate) use fast::is_keyword;
mod indexing_and_expression_bodies;

#[derive(pest_derive::Parser)]
#[grammar = "../../grammar/scene.pest"]
pub(crate) struct SceneParser;

/// What parsing one file (or one `-D` value) needs and collects.
pub struct ParseContext<'a> {
    pub file: FileId,
    pub interner: &'a mut Interner,
    pub functions: &'a mut Vec<FnDef>,
    /// Problems found while building the tree (numbers too large, expressions too deep).
    pub errors: Vec<Diagnostic>,
    /// The deepest an expression tree may be; deeper ones are refused, not evaluated.
    pub max_expression_depth: usize,
    /// How deep the builder is in nested expressions right now.
    depth: usize,
    /// Rules the fast reader entered, backtracked attempts included: a deterministic
    /// measure of parsing work (see [`crate::WorkCounts`]).
    pub steps: u64,
}

impl<'a> ParseContext<'a> {
    pub fn new(
        file: FileId,
        interner: &'a mut Interner,
        functions: &'a mut Vec<FnDef>,
        max_expression_depth: usize,
    ) -> Self {
        ParseContext {
            file,
            interner,
            functions,
            errors: Vec::new(),
            max_expression_depth,
            depth: 0,
            steps: 0,
        }
    }
}

/// Serialises the detailed re-parses of [`parse_rule`]: pest reads its error-detail switch, a
/// process-wide flag, when a parse starts, so only one thread may hold it on at a time.
static ERROR_DETAIL: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Parses `text` as `rule`. Pest's tracking of every attempted token (what makes a syntax
/// error say "expected `,` or `;`") costs more than the parse itself on large files, so the
/// first parse runs without it; only a text that fails is parsed again with it on, which gives
/// exactly the error the tracked parse would have given, since the grammar is deterministic.
fn parse_rule(
    rule: Rule,
    text: &str,
) -> Result<pest::iterators::Pairs<'_, Rule>, pest::error::Error<Rule>> {
    let fast = SceneParser::parse(rule, text);
    if fast.is_ok() {
        return fast;
    }
    // A poisoned lock only means another parse panicked; the flag is still ours to set.
    let _detail = ERROR_DETAIL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    pest::set_error_detail(true);
    let detailed = SceneParser::parse(rule, text);
    pest::set_error_detail(false);
    detailed
}

/// Parses a whole file. On a syntax error, returns that one error (pest stops at the first);
/// otherwise the items, with any tree-building errors left in `cx.errors`.
pub fn parse_file(
    text: &str,
    cx: &mut ParseContext<'_>,
    max_nesting: usize,
) -> Result<Vec<Item>, Diagnostic> {
    let brackets = lexical::scan(text, cx.file, max_nesting, cx.max_expression_depth)?;
    if let Some(items) = fast::parse_file(text, cx) {
        return Ok(items);
    }
    parse_file_with_pest(text, cx, &brackets)
}

/// [`parse_file`] by pest alone, after the lexical pass: the grammar's reference, and the
/// maker of every syntax error.
fn parse_file_with_pest(
    text: &str,
    cx: &mut ParseContext<'_>,
    brackets: &lexical::Brackets,
) -> Result<Vec<Item>, Diagnostic> {
    let mut pairs = parse_rule(Rule::file, text).map_err(|error| {
        let diagnostic = syntax_error::translate(&error, text, cx.file, Some(brackets));
        indexing_and_expression_bodies::expression_body_hint(diagnostic, text, brackets)
    })?;
    let Some(file) = pairs.next() else {
        return Ok(Vec::new());
    };
    let mut items = Vec::new();
    for pair in file.into_inner() {
        if pair.as_rule() != Rule::EOI {
            items.push(cx.item(pair));
        }
    }
    Ok(items)
}

/// Parses the value of a `-D NAME=VALUE`; `offset` is where the value starts in its
/// pseudo-file (after `NAME=`), so spans point into that file.
pub fn parse_define_value(
    text: &str,
    offset: usize,
    cx: &mut ParseContext<'_>,
    max_nesting: usize,
) -> Result<Expr, Diagnostic> {
    let value = text.get(offset..).unwrap_or("");
    let shift = |mut d: Diagnostic| {
        let move_span =
            |s: Span| Span::new(s.file, s.start as usize + offset, s.end as usize + offset);
        d.span = d.span.map(move_span);
        for label in &mut d.secondary {
            label.span = move_span(label.span);
        }
        d
    };
    let brackets =
        lexical::scan(value, cx.file, max_nesting, cx.max_expression_depth).map_err(shift)?;
    let mut pairs = parse_rule(Rule::define_value, value).map_err(|error| {
        shift(syntax_error::translate(
            &error,
            value,
            cx.file,
            Some(&brackets),
        ))
    })?;
    let expr = pairs
        .next()
        .and_then(|p| p.into_inner().find(|p| p.as_rule() == Rule::expr));
    let Some(expr) = expr else {
        return Err(Diagnostic::error(
            "expected a value after `=`",
            Span::new(cx.file, offset, offset),
        ));
    };
    let mut built = cx.expr(expr);
    shift_expr(&mut built, offset);
    Ok(built)
}

/// Moves every span in an expression by `offset` bytes (for `-D` values).
fn shift_expr(expr: &mut Expr, offset: usize) {
    let shift =
        |s: &mut Span| *s = Span::new(s.file, s.start as usize + offset, s.end as usize + offset);
    shift(&mut expr.span);
    match &mut expr.kind {
        ExprKind::Number(_) | ExprKind::Bool(_) | ExprKind::Color(_) => {}
        ExprKind::Vector(parts) => parts.iter_mut().for_each(|p| shift_expr(p, offset)),
        ExprKind::Name(name) => shift(&mut name.ident.span),
        ExprKind::Unary(_, inner) => shift_expr(inner, offset),
        ExprKind::Binary {
            op_span, lhs, rhs, ..
        } => {
            shift(op_span);
            shift_expr(lhs, offset);
            shift_expr(rhs, offset);
        }
        ExprKind::Field { base, field, .. } => {
            shift_expr(base, offset);
            shift(&mut field.span);
        }
        ExprKind::Call(call) => {
            shift(&mut call.span);
            shift(&mut call.callee.span);
            call.args.iter_mut().for_each(|a| shift_expr(a, offset));
        }
        // A material literal in a `-D` value is refused by the resolver; its inner spans
        // are never shown.
        ExprKind::Material(_) => {}
        ExprKind::Array(items) => items.iter_mut().for_each(|i| shift_expr(i, offset)),
        ExprKind::Index { base, index } => {
            shift_expr(base, offset);
            shift_expr(index, offset);
        }
        ExprKind::Str(lit) => {
            shift(&mut lit.span);
            for part in &mut lit.parts {
                if let StrPart::Hole(name) = part {
                    shift(&mut name.ident.span);
                }
            }
        }
    }
}

/// `#rrggbb`: an sRGB colour, stored linear.
pub(super) fn hex_color(text: &str, span: Span) -> Expr {
    let hex = text.trim_start_matches('#');
    let channel = |i: usize| {
        let byte = hex
            .get(i..i + 2)
            .and_then(|h| u8::from_str_radix(h, 16).ok())
            .unwrap_or(0);
        srgb_to_linear(f64::from(byte) / 255.0)
    };
    Expr {
        kind: ExprKind::Color(DVec3::new(channel(0), channel(2), channel(4))),
        span,
    }
}

/// `base.name`; `field_span` covers the `.` and the name.
pub(super) fn field_expr(base: Expr, name: Ident, field_span: Span) -> Expr {
    let span = base.span.to(field_span);
    Expr {
        kind: ExprKind::Field {
            base: Box::new(base),
            field: name,
            component: None,
        },
        span,
    }
}

/// One element of an expression as written: the precedence climb ([`combine`]) turns a
/// list of them into a tree.
pub(super) enum ExprPart {
    Prefix(UnaryOp, Span),
    Operand(Expr),
    Infix(BinaryOp, Span),
}

/// The precedence climb, with explicit stacks instead of recursion. `span` is the whole
/// expression's, for the fallback that well-formed input never reaches.
pub(super) fn combine(parts: impl IntoIterator<Item = ExprPart>, span: Span) -> Expr {
    let mut operands: Vec<Expr> = Vec::new();
    let mut operators: Vec<(BinaryOp, Span)> = Vec::new();
    let mut prefixes: Vec<(UnaryOp, Span)> = Vec::new();

    fn reduce(operands: &mut Vec<Expr>, op: BinaryOp, op_span: Span) {
        let (Some(rhs), Some(lhs)) = (operands.pop(), operands.pop()) else {
            return;
        };
        let span = lhs.span.to(rhs.span);
        operands.push(Expr {
            kind: ExprKind::Binary {
                op,
                op_span,
                lhs: Box::new(lhs),
                rhs: Box::new(rhs),
            },
            span,
        });
    }

    for part in parts {
        match part {
            ExprPart::Prefix(op, op_span) => prefixes.push((op, op_span)),
            ExprPart::Operand(mut operand) => {
                while let Some((op, op_span)) = prefixes.pop() {
                    let span = op_span.to(operand.span);
                    operand = match (op, operand.kind) {
                        // Fold `-2` into a literal so dumps and the evaluator see a number.
                        (UnaryOp::Neg, ExprKind::Number(x)) => Expr {
                            kind: ExprKind::Number(-x),
                            span,
                        },
                        (op, kind) => Expr {
                            kind: ExprKind::Unary(
                                op,
                                Box::new(Expr {
                                    kind,
                                    span: operand.span,
                                }),
                            ),
                            span,
                        },
                    };
                }
                operands.push(operand);
            }
            ExprPart::Infix(op, op_span) => {
                while let Some(&(top, top_span)) = operators.last() {
                    if precedence(top) < precedence(op) {
                        break;
                    }
                    operators.pop();
                    reduce(&mut operands, top, top_span);
                }
                operators.push((op, op_span));
            }
        }
    }
    while let Some((op, op_span)) = operators.pop() {
        reduce(&mut operands, op, op_span);
    }
    operands.pop().unwrap_or(Expr {
        kind: ExprKind::Number(0.0),
        span,
    })
}

/// Operator precedence, loosest first. All binary operators are left-associative.
fn precedence(op: BinaryOp) -> u8 {
    match op {
        BinaryOp::Or => 1,
        BinaryOp::And => 2,
        BinaryOp::Eq | BinaryOp::Ne | BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge => {
            3
        }
        BinaryOp::Add | BinaryOp::Sub => 4,
        BinaryOp::Mul | BinaryOp::Div | BinaryOp::Rem => 5,
    }
}

fn binary_op(rule: Rule) -> Option<BinaryOp> {
    Some(match rule {
        Rule::or => BinaryOp::Or,
        Rule::and => BinaryOp::And,
        Rule::eq => BinaryOp::Eq,
        Rule::ne => BinaryOp::Ne,
        Rule::lt => BinaryOp::Lt,
        Rule::le => BinaryOp::Le,
        Rule::gt => BinaryOp::Gt,
        Rule::ge => BinaryOp::Ge,
        Rule::add => BinaryOp::Add,
        Rule::sub => BinaryOp::Sub,
        Rule::mul => BinaryOp::Mul,
        Rule::div => BinaryOp::Div,
        Rule::rem => BinaryOp::Rem,
        _ => return None,
    })
}

impl ParseContext<'_> {
    fn span(&self, pair: &Pair<'_, Rule>) -> Span {
        let s = pair.as_span();
        Span::new(self.file, s.start(), s.end())
    }

    fn ident(&mut self, pair: &Pair<'_, Rule>) -> Ident {
        Ident {
            sym: self.interner.intern(pair.as_str()),
            span: self.span(pair),
        }
    }

    fn string(&mut self, pair: Pair<'_, Rule>) -> StrLit {
        let span = self.span(&pair);
        let raw = pair
            .into_inner()
            .next()
            .map(|inner| inner.as_str())
            .unwrap_or("");
        self.string_lit(raw, span)
    }

    /// A string literal from its raw text (between the quotes) and its span (with them).
    pub(super) fn string_lit(&mut self, raw: &str, span: Span) -> StrLit {
        let mut value = String::with_capacity(raw.len());
        let mut chars = raw.char_indices();
        while let Some((i, c)) = chars.next() {
            if c != '\\' {
                value.push(c);
                continue;
            }
            match chars.next() {
                Some((_, '"')) => value.push('"'),
                Some((_, '\\')) => value.push('\\'),
                Some((_, 'n')) => value.push('\n'),
                Some((_, 't')) => value.push('\t'),
                other => {
                    // +1 skips the opening quote of the literal.
                    let start = span.start as usize + 1 + i;
                    let end = start + 1 + other.map_or(0, |(_, c)| c.len_utf8());
                    self.errors.push(
                        Diagnostic::error(
                            "unknown escape in a string",
                            Span::new(self.file, start, end),
                        )
                        .with_hint("the escapes are `\\\"`, `\\\\`, `\\n` and `\\t`"),
                    );
                }
            }
        }
        StrLit {
            value,
            span,
            parts: Vec::new(),
        }
    }

    /// A string that may hold `{name}` holes (object and light names, string values).
    fn formatted_string(&mut self, pair: Pair<'_, Rule>) -> StrLit {
        let span = self.span(&pair);
        let raw = pair.into_inner().next().map_or("", |inner| inner.as_str());
        self.formatted_lit(raw, span)
    }

    /// [`Self::string_lit`] with its `{name}` holes split out.
    pub(super) fn formatted_lit(&mut self, raw: &str, span: Span) -> StrLit {
        let mut lit = self.string_lit(raw, span);
        let raw_start = lit.span.start as usize + 1;
        match crate::strings::template(raw, raw_start, self.file, self.interner) {
            Ok(parts) => lit.parts = parts,
            Err(error) => self.errors.push(error),
        }
        lit
    }

    pub(crate) fn item(&mut self, pair: Pair<'_, Rule>) -> Item {
        let span = self.span(&pair);
        let rule = pair.as_rule();
        let mut inner = pair.into_inner();
        // Every item rule starts with a keyword or a name; the helpers below take the
        // children in grammar order.
        let kind = match rule {
            Rule::import_stmt => {
                inner.next();
                let path = match inner.next() {
                    Some(p) => self.string(p),
                    None => StrLit {
                        value: String::new(),
                        span,
                        parts: Vec::new(),
                    },
                };
                ItemKind::Import {
                    path: Box::new(path),
                    file: None,
                }
            }
            Rule::const_stmt | Rule::let_stmt => {
                inner.next();
                let binding = self.binding(&mut inner, span);
                if rule == Rule::const_stmt {
                    ItemKind::Const(binding)
                } else {
                    ItemKind::Let(binding)
                }
            }
            Rule::fn_stmt => {
                inner.next();
                let name = self.next_ident(&mut inner, span);
                let params = inner
                    .next()
                    .map(|p| p.into_inner().map(|i| self.ident(&i)).collect())
                    .unwrap_or_default();
                let body = match inner.peek() {
                    Some(p) if p.as_rule() == Rule::fn_expr_body => self.expr_body(p),
                    _ => self.next_block(&mut inner, span),
                };
                self.functions.push(FnDef {
                    name,
                    params,
                    body,
                    frame_size: 0,
                });
                ItemKind::Fn(self.functions.len() - 1)
            }
            Rule::for_stmt => {
                inner.next();
                let var = self.next_ident(&mut inner, span);
                inner.next(); // `in`
                let start = self.next_expr(&mut inner, span);
                let inclusive = inner.next().is_some_and(|op| op.as_str() == "..=");
                let end = self.next_expr(&mut inner, span);
                let mut step = None;
                if inner.peek().is_some_and(|p| p.as_rule() == Rule::kw_step) {
                    inner.next();
                    step = Some(self.next_expr(&mut inner, span));
                }
                let body = self.next_block(&mut inner, span);
                ItemKind::For {
                    var,
                    slot: Slot::None,
                    start: Box::new(start),
                    end: Box::new(end),
                    inclusive,
                    step: step.map(Box::new),
                    body,
                }
            }
            Rule::while_stmt => {
                inner.next();
                let condition = self.next_expr(&mut inner, span);
                let body = self.next_block(&mut inner, span);
                ItemKind::While {
                    condition: Box::new(condition),
                    body,
                }
            }
            Rule::assign_stmt => {
                let ident = self.next_ident(&mut inner, span);
                let value = self.next_expr(&mut inner, span);
                ItemKind::Assign {
                    target: Name {
                        ident,
                        res: Res::Unresolved,
                    },
                    value,
                }
            }
            Rule::if_stmt => {
                inner.next();
                let condition = self.next_expr(&mut inner, span);
                let then = self.next_block(&mut inner, span);
                inner.next(); // `else`, if present
                let otherwise = inner.next().map(|p| match p.as_rule() {
                    Rule::if_stmt => Else::If(Box::new(self.item(p))),
                    _ => Else::Block(self.block(p)),
                });
                ItemKind::If {
                    condition: Box::new(condition),
                    then,
                    otherwise: otherwise.map(Box::new),
                }
            }
            Rule::return_stmt => {
                inner.next();
                ItemKind::Return(self.next_expr(&mut inner, span))
            }
            Rule::settings_stmt => {
                inner.next();
                ItemKind::Settings(self.next_block(&mut inner, span))
            }
            Rule::camera_stmt => {
                inner.next();
                let kind = self.next_ident(&mut inner, span);
                let body = self.next_block(&mut inner, span);
                ItemKind::Camera {
                    kind,
                    tag: None,
                    body,
                }
            }
            Rule::light_stmt => {
                inner.next();
                let kind = self.next_ident(&mut inner, span);
                let (name, body) = self.optional_name_and_block(&mut inner, span);
                ItemKind::Light {
                    kind,
                    tag: None,
                    name: name.map(Box::new),
                    body,
                }
            }
            Rule::material_stmt => {
                inner.next();
                let name = self.next_ident(&mut inner, span);
                let mut parent = None;
                let mut block = None;
                for p in inner {
                    match p.as_rule() {
                        Rule::ident => {
                            parent = Some(Name {
                                ident: self.ident(&p),
                                res: Res::Unresolved,
                            })
                        }
                        _ => block = Some(self.block(p)),
                    }
                }
                let header_end = parent.as_ref().map_or(name.span.end, |p| p.ident.span.end);
                ItemKind::Material {
                    name,
                    slot: Slot::None,
                    body: Box::new(MaterialBody {
                        header: Span::new(self.file, span.start as usize, header_end as usize),
                        parent,
                        block: block.unwrap_or_else(|| self.empty_block(span)),
                    }),
                }
            }
            Rule::material_prop => {
                let keyword = inner.next();
                let name = match &keyword {
                    Some(k) => self.ident(k),
                    None => self.missing_ident(span),
                };
                let values = match inner.next() {
                    Some(p) if p.as_rule() == Rule::material_body => {
                        let value_span = self.span(&p);
                        let keyword_end = name.span.end as usize;
                        let body = self.material_body(
                            p,
                            Span::new(self.file, span.start as usize, keyword_end),
                        );
                        vec![Expr {
                            kind: ExprKind::Material(Box::new(body)),
                            span: Span::new(
                                self.file,
                                span.start as usize,
                                value_span.end as usize,
                            ),
                        }]
                    }
                    Some(p) => vec![self.expr(p)],
                    None => Vec::new(),
                };
                ItemKind::Property(Property {
                    name,
                    values: PropertyValues::from_vec(values),
                    about: None,
                    block: None,
                    prop: None,
                })
            }
            Rule::call_stmt => {
                let call = match inner.next() {
                    Some(p) => self.call(p),
                    None => Call {
                        callee: self.missing_ident(span),
                        args: Vec::new(),
                        target: CallTarget::Error,
                        span,
                    },
                };
                let modifiers = inner.next().map(|b| self.block(b));
                ItemKind::Call {
                    call: Box::new(call),
                    modifiers,
                }
            }
            Rule::object_stmt => {
                let kind = self.next_ident(&mut inner, span);
                let (name, body) = self.optional_name_and_block(&mut inner, span);
                ItemKind::Object {
                    kind,
                    tag: None,
                    name: name.map(Box::new),
                    body,
                }
            }
            Rule::flag => {
                let name = match inner.next() {
                    Some(k) => self.ident(&k),
                    None => self.missing_ident(span),
                };
                ItemKind::Property(Property {
                    name,
                    values: PropertyValues::Many(Vec::new()),
                    about: None,
                    block: None,
                    prop: None,
                })
            }
            _ => {
                // Rule::property (the grammar has no other item rules).
                let name = self.next_ident(&mut inner, span);
                let mut values = Vec::new();
                let mut about = None;
                let mut block = None;
                let mut after_about = false;
                for p in inner {
                    match p.as_rule() {
                        Rule::kw_about => after_about = true,
                        Rule::block => block = Some(self.block(p)),
                        _ if after_about => about = Some(self.expr(p)),
                        _ => values.push(self.expr(p)),
                    }
                }
                ItemKind::Property(Property {
                    name,
                    values: PropertyValues::from_vec(values),
                    about: about.map(Box::new),
                    block: block.map(Box::new),
                    prop: None,
                })
            }
        };
        Item { kind, span }
    }

    fn binding(&mut self, inner: &mut pest::iterators::Pairs<'_, Rule>, span: Span) -> Binding {
        let name = self.next_ident(inner, span);
        let value = self.next_expr(inner, span);
        Binding {
            name,
            value,
            slot: Slot::None,
        }
    }

    fn optional_name_and_block(
        &mut self,
        inner: &mut pest::iterators::Pairs<'_, Rule>,
        span: Span,
    ) -> (Option<StrLit>, Block) {
        let mut name = None;
        let mut body = None;
        for p in inner {
            match p.as_rule() {
                Rule::string => name = Some(self.formatted_string(p)),
                _ => body = Some(self.block(p)),
            }
        }
        (name, body.unwrap_or_else(|| self.empty_block(span)))
    }

    /// `keyword` is the span of the `material` keyword that precedes the body.
    fn material_body(&mut self, pair: Pair<'_, Rule>, keyword: Span) -> MaterialBody {
        let mut parent: Option<Name> = None;
        let mut block = None;
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => {
                    parent = Some(Name {
                        ident: self.ident(&p),
                        res: Res::Unresolved,
                    })
                }
                _ => block = Some(self.block(p)),
            }
        }
        self.material_body_of(parent, block, keyword)
    }

    /// A material body from its parts; `keyword` is the `material` before it.
    pub(super) fn material_body_of(
        &self,
        parent: Option<Name>,
        block: Option<Block>,
        keyword: Span,
    ) -> MaterialBody {
        let header_end = parent.as_ref().map_or(keyword.end, |p| p.ident.span.end);
        MaterialBody {
            header: Span::new(self.file, keyword.start as usize, header_end as usize),
            parent,
            block: block.unwrap_or_else(|| self.empty_block(keyword)),
        }
    }

    // The grammar guarantees the shape of every rule, so the fallbacks below are never taken
    // on parsed input; they exist so that no `unwrap` sits between user text and a panic.
    fn missing_ident(&mut self, span: Span) -> Ident {
        Ident {
            sym: self.interner.intern("?"),
            span,
        }
    }

    fn empty_block(&self, span: Span) -> Block {
        Block {
            items: Vec::new(),
            span,
        }
    }

    fn next_ident(&mut self, inner: &mut pest::iterators::Pairs<'_, Rule>, span: Span) -> Ident {
        match inner.next() {
            Some(p) => self.ident(&p),
            None => self.missing_ident(span),
        }
    }

    fn next_expr(&mut self, inner: &mut pest::iterators::Pairs<'_, Rule>, span: Span) -> Expr {
        match inner.next() {
            Some(p) => self.expr(p),
            None => Expr {
                kind: ExprKind::Number(0.0),
                span,
            },
        }
    }

    fn next_block(&mut self, inner: &mut pest::iterators::Pairs<'_, Rule>, span: Span) -> Block {
        match inner.next() {
            Some(p) => self.block(p),
            None => self.empty_block(span),
        }
    }

    fn block(&mut self, pair: Pair<'_, Rule>) -> Block {
        let span = self.span(&pair);
        // A block and the item inside it are two levels of every recursive pass.
        self.depth += 2;
        let items = if self.depth > self.max_expression_depth {
            self.too_deep(span);
            Vec::new()
        } else {
            pair.into_inner().map(|p| self.item(p)).collect()
        };
        self.depth -= 2;
        Block { items, span }
    }

    fn call(&mut self, pair: Pair<'_, Rule>) -> Call {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let callee = self.next_ident(&mut inner, span);
        let args = inner
            .next()
            .map(|args| args.into_inner().map(|a| self.expr(a)).collect())
            .unwrap_or_default();
        Call {
            callee,
            args,
            target: CallTarget::Unresolved,
            span,
        }
    }

    /// Builds an `expr` or `arith` pair: prefix operators, operands and infix operators.
    ///
    /// `self.depth` is an upper bound on how deep in the final tree the current node sits:
    /// an expression with `k` operators adds at most `k` levels above its operands. Refusing
    /// trees deeper than the limit keeps every later recursive pass (resolver, evaluator,
    /// drop) within a known stack budget, whatever the input.
    pub(crate) fn expr(&mut self, pair: Pair<'_, Rule>) -> Expr {
        let span = self.span(&pair);
        let added = 1 + pair
            .clone()
            .into_inner()
            .map(|part| match part.as_rule() {
                Rule::postfix => part.into_inner().count(),
                _ => 1,
            })
            .sum::<usize>();
        self.depth += added;
        let built = if self.depth > self.max_expression_depth {
            self.too_deep(span)
        } else {
            self.expr_inner(pair)
        };
        self.depth -= added;
        built
    }

    fn too_deep(&mut self, span: Span) -> Expr {
        let limit = self.max_expression_depth;
        // One report per nest is enough; the outer levels of the same nest stay quiet.
        let already = self
            .errors
            .last()
            .is_some_and(|d| d.message.starts_with("this is nested too deeply"));
        if !already {
            self.errors.push(
                Diagnostic::error(
                    format!(
                        "this is nested too deeply: more than {limit} levels of blocks, brackets and operators"
                    ),
                    Span::new(span.file, span.start as usize, span.start as usize + 1),
                )
                .with_label("the part that goes past the limit starts here")
                .with_hint("split it into smaller parts with `let` or functions"),
            );
        }
        Expr {
            kind: ExprKind::Number(0.0),
            span,
        }
    }

    /// The parts of an `expr` or `arith` pair, combined by precedence.
    fn expr_inner(&mut self, pair: Pair<'_, Rule>) -> Expr {
        let span = self.span(&pair);
        let mut parts = Vec::new();
        for part in pair.into_inner() {
            let rule = part.as_rule();
            match rule {
                Rule::neg => parts.push(ExprPart::Prefix(UnaryOp::Neg, self.span(&part))),
                Rule::not => parts.push(ExprPart::Prefix(UnaryOp::Not, self.span(&part))),
                Rule::postfix => parts.push(ExprPart::Operand(self.postfix(part))),
                _ => {
                    if let Some(op) = binary_op(rule) {
                        parts.push(ExprPart::Infix(op, self.span(&part)));
                    }
                }
            }
        }
        combine(parts, span)
    }

    fn postfix(&mut self, pair: Pair<'_, Rule>) -> Expr {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let mut operand = match inner.next() {
            Some(primary) => self.primary(primary),
            None => Expr {
                kind: ExprKind::Number(0.0),
                span,
            },
        };
        for field in inner {
            if field.as_rule() == Rule::index {
                operand = self.index(operand, field);
                continue;
            }
            let field_span = self.span(&field);
            let name = match field.into_inner().next() {
                Some(ident) => self.ident(&ident),
                None => self.missing_ident(field_span),
            };
            operand = field_expr(operand, name, field_span);
        }
        operand
    }

    /// A number literal; one too large for f64 is an error (and reads as 0).
    pub(super) fn number(&mut self, text: &str, span: Span) -> Expr {
        let value = text.parse::<f64>().unwrap_or(f64::INFINITY);
        if !value.is_finite() {
            self.errors.push(
                Diagnostic::error("this number is too large", span)
                    .with_label("larger than the largest number (about 1.8e308)"),
            );
        }
        Expr {
            kind: ExprKind::Number(if value.is_finite() { value } else { 0.0 }),
            span,
        }
    }

    fn primary(&mut self, pair: Pair<'_, Rule>) -> Expr {
        let span = self.span(&pair);
        let leaf = |kind| Expr { kind, span };
        match pair.as_rule() {
            Rule::number => self.number(pair.as_str(), span),
            Rule::hex_color => hex_color(pair.as_str(), span),
            Rule::kw_true => leaf(ExprKind::Bool(true)),
            Rule::kw_false => leaf(ExprKind::Bool(false)),
            Rule::vector => {
                let mut parts = pair.into_inner().map(|p| self.expr(p));
                let mut next = || {
                    parts.next().unwrap_or(Expr {
                        kind: ExprKind::Number(0.0),
                        span,
                    })
                };
                let (x, y, z) = (next(), next(), next());
                leaf(ExprKind::Vector(Box::new([x, y, z])))
            }
            Rule::material_literal => {
                let mut inner = pair.into_inner();
                let keyword = inner.next().map_or(span, |k| self.span(&k));
                let body = match inner.next() {
                    Some(b) => self.material_body(b, keyword),
                    None => MaterialBody {
                        header: keyword,
                        parent: None,
                        block: self.empty_block(span),
                    },
                };
                leaf(ExprKind::Material(Box::new(body)))
            }
            Rule::call => {
                let call = self.call(pair);
                leaf(ExprKind::Call(Box::new(call)))
            }
            Rule::array => {
                let items = pair.into_inner().map(|p| self.expr(p)).collect();
                leaf(ExprKind::Array(items))
            }
            Rule::string => {
                let lit = self.formatted_string(pair);
                leaf(ExprKind::Str(Box::new(lit)))
            }
            Rule::ident => {
                let ident = self.ident(&pair);
                leaf(ExprKind::Name(Name {
                    ident,
                    res: Res::Unresolved,
                }))
            }
            _ => {
                // Rule::paren: the inner expression, with the brackets' span.
                let inner = match pair.into_inner().next() {
                    Some(e) => self.expr(e),
                    None => Expr {
                        kind: ExprKind::Number(0.0),
                        span,
                    },
                };
                Expr {
                    kind: inner.kind,
                    span,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parses `input` and returns the tree dump, or the rendered syntax error.
    fn check(name: &str, input: &str) {
        let mut interner = Interner::default();
        let mut functions = Vec::new();
        let mut sources = whitted_ir::SourceMap::new();
        let file = sources.add(whitted_ir::SourceFile::new("test.scene", input));
        let mut cx = ParseContext::new(file, &mut interner, &mut functions, 4096);
        let result = parse_file(input, &mut cx, 256);
        let errors = std::mem::take(&mut cx.errors);
        let output = match result {
            Ok(items) => {
                let mut out = crate::ast_dump::dump(&items, &functions, &interner);
                out.push_str(&crate::render_diagnostics(&sources, &errors, false));
                out
            }
            Err(diagnostic) => crate::render_diagnostics(&sources, &[diagnostic], false),
        };
        insta::assert_snapshot!(name, format!("{input}\n---\n{output}"));
    }

    #[test]
    fn precedence_follows_the_table() {
        check(
            "precedence",
            "let a = 1 + 2 * 3 - -4 % 5 / 6;\n\
             let b = !x || y && a < 2 == true;\n\
             let c = -v.x * <1, 2 + 3, -4>.y;\n\
             let d = (1 + 2) * 3;",
        );
    }

    #[test]
    fn every_item_kind_parses() {
        check(
            "items",
            r#"import "lib.scene"
const N = 10;
fn f(a, b,) { return a + b; }
for i in 0..N { for j in 1..=3 { sphere { } } }
if a > 1 { } else if b { } else { }
settings { width 640 shadows filtered }
camera perspective { eye <0, 0, -5> }
light point "key" { position <1, 2, 3> }
material glass : base { ior 1.5 diffuse checker(white, #ff8000, 2) { rotate <0, 45, 0> } }
sphere "ball" { material glass material { diffuse red } material : glass { ior 1 } }
cylinder { open rotate 30 about <0, 1, 0> }
triangle { vertices <0, 0, 0>, <1, 0, 0>, <0, 1, 0> }
ring(12, 2) { translate <0, 1, 0> }
let m = material : glass { ior 2 };
"#,
        );
    }

    #[test]
    fn a_range_is_not_a_number_with_a_fraction() {
        check("range", "for i in 0..10 { } for j in n..m { }");
    }

    #[test]
    fn deep_prefix_runs_and_long_chains_are_refused_not_overflowed() {
        let minus = format!("let a = {}1;", "-".repeat(100_000));
        let chain = format!("let a = 1{};", " + 1".repeat(100_000));
        for input in [minus, chain] {
            let mut interner = Interner::default();
            let mut functions = Vec::new();
            let mut cx = ParseContext::new(FileId(0), &mut interner, &mut functions, 4096);
            // The lexical pass counts the operators and refuses the run before pest sees it.
            match parse_file(&input, &mut cx, 256) {
                Err(error) => assert!(
                    error.message.starts_with("this expression is too long"),
                    "{}",
                    error.message
                ),
                Ok(_) => panic!("a run of 100,000 operators was accepted"),
            }
        }
        // Just inside the count, the tree's depth bound still refuses what operators and
        // brackets build together.
        let mixed = format!("let a = {}1{};", "-(".repeat(200), ")".repeat(200));
        let mut interner = Interner::default();
        let mut functions = Vec::new();
        let mut cx = ParseContext::new(FileId(0), &mut interner, &mut functions, 300);
        let result = parse_file(&mixed, &mut cx, 256);
        assert!(result.is_ok());
        assert_eq!(cx.errors.len(), 1, "{:?}", cx.errors);
        assert!(cx.errors[0]
            .message
            .starts_with("this is nested too deeply"));
    }
}
