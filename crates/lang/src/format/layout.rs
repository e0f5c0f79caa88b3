//! The layout rules: the tokens of a file, grouped into blocks and items, printed again
//! with canonical whitespace. Only whitespace changes; which tokens share a line follows the
//! rules below, each decided from the tokens and from where the author broke lines, so that
//! formatting formatted text changes nothing.
//!
//! - Indentation is 4 spaces per enclosing block; a line that continues an item (the author
//!   broke a long expression) is indented one level more.
//! - A block stays on one line, `{ a b }`, when it was written on one line and the line fits
//!   in 100 columns; otherwise `{` ends its line, its items follow one level deeper and `}`
//!   gets a line of its own. An empty block is `{ }`.
//! - Items the author wrote on one line stay together while the line fits (so
//!   `width 640 height 480` stays one line); a line that does not fit gets one item each.
//! - Blank lines between items are kept, at most one; none after `{`, before `}` or at the
//!   ends of the file.
//! - Spacing inside a line: a space after `,` and around infix operators, `=` and `:`, none
//!   inside `( )`, `[ ]` and `< >`, after a prefix `-` or `!`, around `.` and `..`, or
//!   before a call's `(`.
//! - Comments stay where they were: on their own line (indented like what follows), or at
//!   the end of a line with the spaces the author put before them.

use super::structure::Structure;
use super::tokens::{Kind, Role, Token};

/// Columns a line may take before its items or blocks are split.
const MAX_WIDTH: usize = 100;
const INDENT: &str = "    ";

/// A block: its `{`, what is inside, its `}` (indices into the tokens).
struct BlockNode {
    open: usize,
    entries: Vec<Entry>,
    close: usize,
}

/// What a block or the file holds: items and the comments between them.
enum Entry {
    Item(Vec<Node>),
    Comment(usize),
}

enum Node {
    Token(usize),
    Block(BlockNode),
}

/// The tokens did not line up with the syntax tree: a bug in the formatter, never the
/// user's text (which parsed). Formatting is then refused rather than guessed.
#[derive(Debug)]
pub(super) struct Mismatch(pub u32);

struct Builder<'a> {
    tokens: &'a [Token],
    structure: &'a Structure,
    next: usize,
}

impl Builder<'_> {
    fn entries(&mut self, end: u32, items: &[(u32, u32)]) -> Result<Vec<Entry>, Mismatch> {
        let mut entries = Vec::new();
        let mut items = items.iter().peekable();
        while let Some(token) = self.tokens.get(self.next) {
            if token.start >= end {
                break;
            }
            if token.is_comment() {
                entries.push(Entry::Comment(self.next));
                self.next += 1;
                continue;
            }
            let Some(&(start, item_end)) = items.next() else {
                return Err(Mismatch(token.start));
            };
            if token.start != start {
                return Err(Mismatch(token.start));
            }
            entries.push(Entry::Item(self.nodes(item_end)?));
        }
        if items.next().is_some() {
            return Err(Mismatch(end));
        }
        Ok(entries)
    }

    /// The tokens and blocks of one item, up to `end`.
    fn nodes(&mut self, end: u32) -> Result<Vec<Node>, Mismatch> {
        let mut nodes = Vec::new();
        while let Some(token) = self.tokens.get(self.next) {
            if token.start >= end {
                break;
            }
            if let Some(shape) = self.structure.blocks.get(&token.start) {
                let open = self.next;
                self.next += 1;
                let entries = self.entries(shape.close, &shape.items)?;
                let close = self.next;
                match self.tokens.get(close) {
                    Some(t) if t.start == shape.close => self.next += 1,
                    _ => return Err(Mismatch(shape.close)),
                }
                nodes.push(Node::Block(BlockNode {
                    open,
                    entries,
                    close,
                }));
            } else {
                nodes.push(Node::Token(self.next));
                self.next += 1;
            }
        }
        Ok(nodes)
    }
}

/// Prints the file laid out by the rules above.
pub(super) fn print(
    text: &str,
    tokens: &[Token],
    structure: &Structure,
) -> Result<String, Mismatch> {
    let mut builder = Builder {
        tokens,
        structure,
        next: 0,
    };
    let entries = builder.entries(text.len() as u32 + 1, &structure.file_items)?;
    if builder.next != tokens.len() {
        return Err(Mismatch(tokens.get(builder.next).map_or(0, |t| t.start)));
    }
    let mut printer = Printer {
        text,
        tokens,
        out: String::new(),
    };
    printer.entries(&entries, 0);
    if !printer.out.is_empty() {
        printer.out.push('\n');
    }
    Ok(printer.out)
}

struct Printer<'a> {
    text: &'a str,
    tokens: &'a [Token],
    out: String,
}

fn first_token(entry: &Entry) -> Option<usize> {
    match entry {
        Entry::Comment(k) => Some(*k),
        Entry::Item(nodes) => nodes.first().map(|node| match node {
            Node::Token(k) => *k,
            Node::Block(block) => block.open,
        }),
    }
}

fn last_token(nodes: &[Node]) -> Option<usize> {
    nodes.last().map(|node| match node {
        Node::Token(k) => *k,
        Node::Block(block) => block.close,
    })
}

impl<'a> Printer<'a> {
    fn source(&self, k: usize) -> &'a str {
        let t = &self.tokens[k];
        let text = self.text;
        let s = &text[t.start as usize..t.end as usize];
        if t.kind == Kind::LineComment {
            // A line comment reads up to the line break; a `\r` or spaces before it are
            // whitespace to the reader and would be invisible trailing space in the output.
            s.trim_end()
        } else {
            s
        }
    }

    fn newline(&mut self, depth: usize) {
        // No trailing spaces on a line, and none on a blank one.
        while self.out.ends_with(' ') {
            self.out.pop();
        }
        self.out.push('\n');
        for _ in 0..depth {
            self.out.push_str(INDENT);
        }
    }

    /// The space between two tokens on one line (the second not a comment).
    fn space(&self, a: usize, b: usize) -> &'static str {
        let (ta, tb) = (&self.tokens[a], &self.tokens[b]);
        if ta.is_comment() {
            return " ";
        }
        let (sa, sb) = (self.source(a), self.source(b));
        let none = matches!(sb, "," | ";" | ")" | "]")
            || matches!(tb.role, Role::CallOpen | Role::ParamsOpen | Role::IndexOpen)
            || matches!(sa, "(" | "[")
            || ta.role == Role::VectorOpen
            || tb.role == Role::VectorClose
            || ta.role == Role::Unary
            || ta.role == Role::FieldDot
            || tb.role == Role::FieldDot
            || ta.role == Role::Range
            || tb.role == Role::Range;
        if none {
            ""
        } else {
            " "
        }
    }

    /// The space before a comment that shares a line with what comes before it: the
    /// author's (aligned trailing comments stay aligned), at least one.
    fn comment_space(&self, k: usize) -> String {
        let n = self.tokens[k].spaces_before.unwrap_or(1).max(1);
        " ".repeat(n as usize)
    }

    /// Whether the source has a line break anywhere from token `a` to token `b`.
    fn spans_lines(&self, a: usize, b: usize) -> bool {
        let (start, end) = (self.tokens[a].start as usize, self.tokens[b].end as usize);
        self.text[start..end].contains('\n')
    }

    /// The item on one line, if the author wrote it on one line.
    fn flat_item(&self, nodes: &[Node]) -> Option<String> {
        let first = match nodes.first()? {
            Node::Token(k) => *k,
            Node::Block(block) => block.open,
        };
        if self.spans_lines(first, last_token(nodes)?) {
            return None;
        }
        let mut line = String::new();
        let mut previous = None;
        self.flat_nodes(nodes, &mut line, &mut previous);
        Some(line)
    }

    fn flat_nodes(&self, nodes: &[Node], line: &mut String, previous: &mut Option<usize>) {
        for node in nodes {
            match node {
                Node::Token(k) => self.flat_token(*k, line, previous),
                Node::Block(block) => {
                    self.flat_token(block.open, line, previous);
                    for entry in &block.entries {
                        match entry {
                            Entry::Comment(k) => self.flat_token(*k, line, previous),
                            Entry::Item(inner) => {
                                // Items in a block are always a space apart.
                                line.push(' ');
                                *previous = None;
                                self.flat_nodes(inner, line, previous);
                            }
                        }
                    }
                    line.push(' ');
                    *previous = None;
                    self.flat_token(block.close, line, previous);
                }
            }
        }
    }

    fn flat_token(&self, k: usize, line: &mut String, previous: &mut Option<usize>) {
        if let Some(p) = *previous {
            if self.tokens[k].is_comment() {
                line.push_str(&self.comment_space(k));
            } else {
                line.push_str(self.space(p, k));
            }
        }
        line.push_str(self.source(k));
        *previous = Some(k);
    }

    /// Width of a line as the rules measure it: a trailing line comment does not count.
    fn width(&self, line: &str, depth: usize) -> usize {
        let code = match line.find("//") {
            // Only a comment token starts with `//` outside strings; find the real one.
            Some(_) => self.code_part(line),
            None => line,
        };
        depth * INDENT.len() + code.trim_end().chars().count()
    }

    fn code_part<'l>(&self, line: &'l str) -> &'l str {
        // Walk the line as tokens would: skip strings and block comments.
        let bytes = line.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            match bytes[i] {
                b'"' => {
                    i += 1;
                    while i < bytes.len() && bytes[i] != b'"' {
                        i += if bytes[i] == b'\\' { 2 } else { 1 };
                    }
                    i += 1;
                }
                b'/' if bytes.get(i + 1) == Some(&b'*') => {
                    i = line[i + 2..]
                        .find("*/")
                        .map_or(bytes.len(), |n| i + 2 + n + 2);
                }
                b'/' if bytes.get(i + 1) == Some(&b'/') => return &line[..i],
                _ => i += 1,
            }
        }
        line
    }

    /// A block's or the file's entries at `depth`, each group of entries the author put on
    /// one line kept there when it fits. The first group continues the current line.
    fn entries(&mut self, entries: &[Entry], depth: usize) {
        let mut groups: Vec<&[Entry]> = Vec::new();
        let mut start = 0;
        for (i, entry) in entries.iter().enumerate() {
            let breaks = first_token(entry).is_some_and(|k| self.tokens[k].newlines_before > 0);
            if i > start && breaks {
                groups.push(&entries[start..i]);
                start = i;
            }
        }
        if start < entries.len() {
            groups.push(&entries[start..]);
        }
        for (g, group) in groups.iter().enumerate() {
            if g > 0 {
                let blank =
                    first_token(&group[0]).is_some_and(|k| self.tokens[k].newlines_before > 1);
                if blank {
                    self.newline(0);
                }
                self.newline(depth);
            }
            self.group(group, depth);
        }
    }

    fn group(&mut self, group: &[Entry], depth: usize) {
        if let Some(line) = self.flat_group(group) {
            if self.width(&line, depth) <= MAX_WIDTH {
                self.out.push_str(&line);
                return;
            }
        }
        // One item per line; comments stay on the line of the item before them (or of the
        // first item, when they lead the group).
        let mut seen_item = false;
        let mut previous: Option<usize> = None;
        for entry in group {
            match entry {
                Entry::Comment(k) => {
                    if previous.is_some() {
                        self.out.push_str(&self.comment_space(*k));
                    }
                    self.out.push_str(self.source(*k));
                    previous = Some(*k);
                }
                Entry::Item(nodes) => {
                    if seen_item {
                        self.newline(depth);
                    } else if previous.is_some() {
                        self.out.push(' ');
                    }
                    seen_item = true;
                    let line_start = self.out.rfind('\n').map_or(0, |n| n + 1);
                    let prefix = self.out[line_start..].trim_start().chars().count();
                    match self.flat_item(nodes) {
                        Some(line)
                            if self.width(&line, depth) + prefix + usize::from(prefix > 0)
                                <= MAX_WIDTH =>
                        {
                            self.out.push_str(&line)
                        }
                        _ => self.broken_item(nodes, depth),
                    }
                    previous = last_token(nodes);
                }
            }
        }
    }

    /// The group on one line, if every part of it was written on one line.
    fn flat_group(&self, group: &[Entry]) -> Option<String> {
        let mut line = String::new();
        for (i, entry) in group.iter().enumerate() {
            match entry {
                Entry::Comment(k) => {
                    if i > 0 {
                        line.push_str(&self.comment_space(*k));
                    }
                    if self.source(*k).contains('\n') {
                        return None;
                    }
                    line.push_str(self.source(*k));
                }
                Entry::Item(nodes) => {
                    if i > 0 {
                        line.push(' ');
                    }
                    line.push_str(&self.flat_item(nodes)?);
                }
            }
        }
        Some(line)
    }

    /// An item over several lines: its blocks opened up, and the line breaks the author
    /// put between its tokens kept (as continuation lines one level deeper).
    fn broken_item(&mut self, nodes: &[Node], depth: usize) {
        let mut previous: Option<usize> = None;
        self.broken_nodes(nodes, depth, &mut previous);
    }

    fn broken_nodes(&mut self, nodes: &[Node], depth: usize, previous: &mut Option<usize>) {
        for node in nodes {
            match node {
                Node::Token(k) => self.broken_token(*k, depth, previous),
                Node::Block(block) => {
                    self.broken_token(block.open, depth, previous);
                    self.block(block, depth);
                    *previous = Some(block.close);
                }
            }
        }
    }

    fn broken_token(&mut self, k: usize, depth: usize, previous: &mut Option<usize>) {
        if let Some(p) = *previous {
            let token = &self.tokens[k];
            let after_line_comment = self.tokens[p].kind == Kind::LineComment;
            // `{` and what follows a `}` in the same item (`} else {`) join their line.
            let joins = !after_line_comment
                && (self.structure_open(k)
                    || (self.source(p) == "}" && !token.is_comment())
                    || token.newlines_before == 0);
            if !joins {
                self.newline(depth + 1);
            } else if token.is_comment() {
                let space = self.comment_space(k);
                self.out.push_str(&space);
            } else {
                self.out.push_str(self.space(p, k));
            }
        }
        self.out.push_str(self.source(k));
        *previous = Some(k);
    }

    /// Whether token `k` is a block's `{` (every `{` in the grammar opens a block).
    fn structure_open(&self, k: usize) -> bool {
        self.tokens[k].kind == Kind::Punct && self.source(k) == "{"
    }

    /// Whether the last entry of a block is a block comment (after which `}` may follow on
    /// the same line, as it could not after a line comment).
    fn last_is_block_comment(&self, block: &BlockNode) -> bool {
        matches!(block.entries.last(), Some(Entry::Comment(k)) if self.tokens[*k].kind == Kind::BlockComment)
    }

    /// A block over several lines; `{` is already printed.
    fn block(&mut self, block: &BlockNode, depth: usize) {
        if block.entries.is_empty() {
            self.out.push_str(" }");
            return;
        }
        // Comments right after `{`, on its line, stay there.
        let mut rest = &block.entries[..];
        while let Some((Entry::Comment(k), tail)) = rest.split_first() {
            if self.tokens[*k].newlines_before > 0 {
                break;
            }
            let space = self.comment_space(*k);
            self.out.push_str(&space);
            self.out.push_str(self.source(*k));
            rest = tail;
        }
        if rest.is_empty() && !self.out.ends_with('\n') && self.last_is_block_comment(block) {
            // `{ /* nothing yet */ }`: nothing needs a line of its own.
            self.out.push_str(" }");
            return;
        }
        if !rest.is_empty() {
            self.newline(depth + 1);
            self.entries(rest, depth + 1);
        }
        self.newline(depth);
        self.out.push_str(self.source(block.close));
    }
}
