//! How a command failed, and the one rule that turns that into the exit code.
//!
//! The rule (README, "Exit codes"): 2 when the command line is wrong (a flag, its value, a
//! size past the limits, a pixel outside the image, a `--set` or `-D` that does not apply);
//! 1 when the scene or a file is (scene errors, a file missing or unreadable, an output that
//! cannot be written); 0 on success; 128 + N when stopped by signal N. Each command says
//! which kind its failure is by the variant it returns; only this module maps kinds to codes.

/// How a command failed, so that `main` can pick the exit code and print one clear line.
pub enum Failure {
    /// The scene had errors; its diagnostics were already printed. Exit 1.
    SceneErrors,
    /// The scene or a file is at fault (a missing file, an unwritable output): one line,
    /// naming the file. Exit 1.
    Message(String),
    /// The command line is at fault, and clap could not tell (a pixel outside the image, a
    /// size past the limits, a `--set` the compiler refused): one line quoting the flag.
    /// Exit 2, clap's own code for the errors it finds.
    Usage(String),
    /// Stopped by this signal after cleaning up: exit as a shell expects (128 + its number).
    Signal(i32),
}

impl Failure {
    /// The exit status for this failure.
    pub fn exit_code(&self) -> u8 {
        match self {
            Failure::SceneErrors | Failure::Message(_) => 1,
            Failure::Usage(_) => 2,
            Failure::Signal(signal) => 128u8.saturating_add(u8::try_from(*signal).unwrap_or(0)),
        }
    }

    /// The line to print on stderr, if the failure has not been reported already.
    pub fn message(&self) -> Option<&str> {
        match self {
            Failure::Message(message) | Failure::Usage(message) => Some(message),
            Failure::SceneErrors | Failure::Signal(_) => None,
        }
    }
}

/// An IO error that reaches a command unexplained is a file's (exit 1).
impl From<std::io::Error> for Failure {
    fn from(error: std::io::Error) -> Self {
        Failure::Message(error.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_has_its_code() {
        assert_eq!(Failure::SceneErrors.exit_code(), 1);
        assert_eq!(Failure::Message("m".into()).exit_code(), 1);
        assert_eq!(Failure::Usage("u".into()).exit_code(), 2);
        assert_eq!(Failure::Signal(2).exit_code(), 130);
        assert_eq!(Failure::Signal(15).exit_code(), 143);
    }
}
