//! The one diagnostic type shared by the language, the validator, the CLI and the debugger.
//!
//! Rendering (source line, underline, colours) happens only at the edges; here it is data.

use crate::source::Span;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    Note,
    Warning,
    Error,
}

/// A span with a message, e.g. "the block opened here".
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    pub span: Span,
    pub message: String,
}

/// A located message about the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub message: String,
    /// Where the problem is; `None` only for problems no source text made (a bad `-D`).
    pub span: Option<Span>,
    /// What to say under the primary underline ("expected a number here").
    pub label: Option<String>,
    /// Other places worth showing ("first defined here").
    pub secondary: Vec<Label>,
    /// Suggestions, each a sentence ("did you mean `glass`?").
    pub hints: Vec<String>,
}

impl Diagnostic {
    pub fn error(message: impl Into<String>, span: Span) -> Self {
        Self::new(Severity::Error, message, Some(span))
    }

    pub fn warning(message: impl Into<String>, span: Span) -> Self {
        Self::new(Severity::Warning, message, Some(span))
    }

    pub fn note(message: impl Into<String>, span: Span) -> Self {
        Self::new(Severity::Note, message, Some(span))
    }

    pub fn new(severity: Severity, message: impl Into<String>, span: Option<Span>) -> Self {
        Diagnostic {
            severity,
            message: message.into(),
            span: span.filter(|s| !s.is_detached()),
            label: None,
            secondary: Vec::new(),
            hints: Vec::new(),
        }
    }

    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    pub fn with_secondary(mut self, span: Span, message: impl Into<String>) -> Self {
        if !span.is_detached() {
            self.secondary.push(Label {
                span,
                message: message.into(),
            });
        }
        self
    }

    pub fn with_hint(mut self, hint: impl Into<String>) -> Self {
        self.hints.push(hint.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}
