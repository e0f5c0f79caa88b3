//! The syntax tree: what the parser builds and the resolver annotates in place (slots,
//! resolved kinds), so that the evaluator reads one tree with every name already looked up.

use whitted_ir::{DVec3, Span};

use crate::intern::Sym;
use crate::schema::{CameraTag, LightTag, ObjectTag, Prop};

/// Index of a file in [`Program::files`] (the same order as the source map).
pub type FileIndex = usize;
/// Index of a function in [`Program::functions`].
pub type FnId = usize;

/// Every parsed file and every function definition, across all imports.
#[derive(Debug, Default)]
pub struct Program {
    pub files: Vec<FileAst>,
    pub functions: Vec<FnDef>,
}

#[derive(Debug)]
pub struct FileAst {
    pub items: Vec<Item>,
    /// Slots used by locals of the file's top-level blocks (loop variables and the like).
    pub frame_size: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ident {
    pub sym: Sym,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct StrLit {
    pub value: String,
    pub span: Span,
    /// The text split at its `{name}` holes (see [`crate::strings`]); empty for a string
    /// without holes and for strings that are never formatted (import paths).
    pub parts: Vec<StrPart>,
}

/// A piece of a formatted string: `"ball {i}"` is `Text("ball ")` then `Hole(i)`.
#[derive(Clone, Debug)]
pub enum StrPart {
    Text(String),
    Hole(Name),
}

#[derive(Debug)]
pub struct Block {
    pub items: Vec<Item>,
    pub span: Span,
}

#[derive(Debug)]
pub struct Item {
    pub kind: ItemKind,
    pub span: Span,
}

/// Where a binding lives at run time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// Not yet assigned (before resolution) or failed to resolve.
    None,
    /// An index into the current call frame.
    Local(u32),
    /// An index into the program-wide table of top-level bindings.
    Global(u32),
}

/// `let NAME = value;` or `const NAME = value;`.
#[derive(Debug)]
pub struct Binding {
    pub name: Ident,
    pub value: Expr,
    pub slot: Slot,
}

#[derive(Debug)]
pub struct FnDef {
    pub name: Ident,
    pub params: Vec<Ident>,
    pub body: Block,
    /// Slots of the call frame: parameters first, then locals.
    pub frame_size: u32,
}

#[derive(Debug)]
pub enum Else {
    If(Box<Item>),
    Block(Block),
}

/// `{ ... }` after `material`, with an optional `: parent`.
#[derive(Debug)]
pub struct MaterialBody {
    /// `material`, `material glass` or `material tinted : glass`: where the IR says the
    /// material was made.
    pub header: Span,
    pub parent: Option<Name>,
    pub block: Block,
}

#[derive(Debug)]
pub struct Property {
    pub name: Ident,
    pub values: PropertyValues,
    /// `rotate 30 about <1, 1, 0>`. Boxed, like the other rare parts of items, so that an
    /// item stays small: scenes written by programs hold millions of them.
    pub about: Option<Box<Expr>>,
    /// `diffuse checker(a, b, 1) { rotate <0, 45, 0> }`.
    pub block: Option<Box<Block>>,
    /// Filled by the resolver when the name is valid in its block.
    pub prop: Option<Prop>,
}

/// A property's values: almost always exactly one, kept inline rather than in a vector of
/// its own (a scene written by a program has millions of properties). Reads as a slice.
#[derive(Debug)]
pub enum PropertyValues {
    One(Expr),
    Many(Vec<Expr>),
}

impl PropertyValues {
    pub fn from_vec(mut values: Vec<Expr>) -> Self {
        match values.pop() {
            Some(only) if values.is_empty() => PropertyValues::One(only),
            Some(last) => {
                values.push(last);
                PropertyValues::Many(values)
            }
            None => PropertyValues::Many(values),
        }
    }

    pub fn as_slice(&self) -> &[Expr] {
        match self {
            PropertyValues::One(only) => std::slice::from_ref(only),
            PropertyValues::Many(values) => values,
        }
    }

    pub fn as_mut_slice(&mut self) -> &mut [Expr] {
        match self {
            PropertyValues::One(only) => std::slice::from_mut(only),
            PropertyValues::Many(values) => values,
        }
    }
}

impl std::ops::Deref for PropertyValues {
    type Target = [Expr];

    fn deref(&self) -> &[Expr] {
        self.as_slice()
    }
}

impl std::ops::DerefMut for PropertyValues {
    fn deref_mut(&mut self) -> &mut [Expr] {
        self.as_mut_slice()
    }
}

impl<'a> IntoIterator for &'a PropertyValues {
    type Item = &'a Expr;
    type IntoIter = std::slice::Iter<'a, Expr>;

    fn into_iter(self) -> Self::IntoIter {
        self.as_slice().iter()
    }
}

impl<'a> IntoIterator for &'a mut PropertyValues {
    type Item = &'a mut Expr;
    type IntoIter = std::slice::IterMut<'a, Expr>;

    fn into_iter(self) -> Self::IntoIter {
        self.as_mut_slice().iter_mut()
    }
}

#[derive(Debug)]
pub enum ItemKind {
    Import {
        path: Box<StrLit>,
        /// Filled by the loader: which file the path names.
        file: Option<FileIndex>,
    },
    Const(Binding),
    Let(Binding),
    Fn(FnId),
    For {
        var: Ident,
        slot: Slot,
        start: Box<Expr>,
        end: Box<Expr>,
        inclusive: bool,
        /// `for i in 0..10 step 2`.
        step: Option<Box<Expr>>,
        body: Block,
    },
    /// `while condition { ... }`.
    While {
        condition: Box<Expr>,
        body: Block,
    },
    /// `name = value;`: a new value for a `let` binding.
    Assign {
        target: Name,
        value: Expr,
    },
    If {
        condition: Box<Expr>,
        then: Block,
        otherwise: Option<Box<Else>>,
    },
    Return(Expr),
    Settings(Block),
    Camera {
        kind: Ident,
        tag: Option<CameraTag>,
        body: Block,
    },
    Light {
        kind: Ident,
        tag: Option<LightTag>,
        name: Option<Box<StrLit>>,
        body: Block,
    },
    Material {
        name: Ident,
        slot: Slot,
        body: Box<MaterialBody>,
    },
    Object {
        kind: Ident,
        tag: Option<ObjectTag>,
        name: Option<Box<StrLit>>,
        body: Block,
    },
    Call {
        call: Box<Call>,
        modifiers: Option<Block>,
    },
    Property(Property),
}

#[derive(Debug)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    Neg,
    Not,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Or,
    And,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
    Rem,
}

impl BinaryOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinaryOp::Or => "||",
            BinaryOp::And => "&&",
            BinaryOp::Eq => "==",
            BinaryOp::Ne => "!=",
            BinaryOp::Lt => "<",
            BinaryOp::Le => "<=",
            BinaryOp::Gt => ">",
            BinaryOp::Ge => ">=",
            BinaryOp::Add => "+",
            BinaryOp::Sub => "-",
            BinaryOp::Mul => "*",
            BinaryOp::Div => "/",
            BinaryOp::Rem => "%",
        }
    }
}

/// What a name in an expression refers to, as the resolver found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Res {
    Unresolved,
    Local(u32),
    Global(u32),
    Builtin(crate::builtins::Constant),
    /// A word such as `filtered` in `shadows filtered`: its index in the property's words.
    Word(u8),
    /// Resolution failed and was reported.
    Error,
}

#[derive(Clone, Copy, Debug)]
pub struct Name {
    pub ident: Ident,
    pub res: Res,
}

/// What a call calls, as the resolver found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CallTarget {
    Unresolved,
    Builtin(crate::builtins::Function),
    User(FnId),
    Error,
}

#[derive(Debug)]
pub struct Call {
    pub callee: Ident,
    pub args: Vec<Expr>,
    pub target: CallTarget,
    pub span: Span,
}

/// Which component `.x`/`.r` (0), `.y`/`.g` (1) or `.z`/`.b` (2) reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Component(pub u8);

#[derive(Debug)]
pub enum ExprKind {
    Number(f64),
    Bool(bool),
    /// A `#rrggbb` colour, already converted to linear RGB.
    Color(DVec3),
    Vector(Box<[Expr; 3]>),
    Name(Name),
    Unary(UnaryOp, Box<Expr>),
    Binary {
        op: BinaryOp,
        op_span: Span,
        lhs: Box<Expr>,
        rhs: Box<Expr>,
    },
    Field {
        base: Box<Expr>,
        field: Ident,
        component: Option<Component>,
    },
    Call(Box<Call>),
    Material(Box<MaterialBody>),
    /// `[a, b, c]`.
    Array(Vec<Expr>),
    /// `base[index]`.
    Index {
        base: Box<Expr>,
        index: Box<Expr>,
    },
    /// `"ball {i}"`.
    Str(Box<StrLit>),
}
