//! `cargo xtask bench`'s command line.

use anyhow::{bail, Context};

pub(super) const FLAGS: &str = "--size WxH, --only TEXT, --base REV, --no-base, --programs, \
                                --mesh, --csg, --lsp";

/// What the bench compares the work tree's binary with.
#[derive(Debug, PartialEq, Eq)]
pub(super) enum BaseRequest {
    /// `HEAD~1` when the work tree is clean, `HEAD` when it has changes.
    Default,
    /// `--base REV`.
    Revision(String),
    /// `--no-base`: the work tree's binary alone.
    Nothing,
}

#[derive(Debug, PartialEq, Eq)]
pub(super) struct Options {
    pub width: u32,
    pub height: u32,
    /// `--only TEXT`: only the render rows whose label contains TEXT.
    pub only: Option<String>,
    pub base: BaseRequest,
    pub programs: bool,
    pub mesh: bool,
    pub csg: bool,
    pub lsp: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            width: 640,
            height: 480,
            only: None,
            base: BaseRequest::Default,
            programs: false,
            mesh: false,
            csg: false,
            lsp: false,
        }
    }
}

pub(super) fn parse(args: &[String]) -> anyhow::Result<Options> {
    let mut options = Options::default();
    let mut iter = args.iter();
    while let Some(arg) = iter.next() {
        match arg.as_str() {
            "--size" => {
                let value = iter.next().context("--size needs WxH")?;
                let (w, h) = value
                    .split_once('x')
                    .context("--size needs WxH, e.g. 320x240")?;
                options.width = w.parse().context("bad width")?;
                options.height = h.parse().context("bad height")?;
            }
            "--only" => {
                let text = iter
                    .next()
                    .context("--only needs a part of a row's label")?;
                options.only = Some(text.clone());
            }
            "--base" => {
                let rev = iter
                    .next()
                    .context("--base needs a revision, e.g. HEAD~1")?;
                if options.base == BaseRequest::Nothing {
                    bail!("--base and --no-base contradict each other");
                }
                options.base = BaseRequest::Revision(rev.clone());
            }
            "--no-base" => {
                if matches!(options.base, BaseRequest::Revision(_)) {
                    bail!("--base and --no-base contradict each other");
                }
                options.base = BaseRequest::Nothing;
            }
            "--programs" => options.programs = true,
            "--mesh" => options.mesh = true,
            "--csg" => options.csg = true,
            "--lsp" => options.lsp = true,
            other => bail!("unknown bench option `{other}` (known: {FLAGS})"),
        }
    }
    Ok(options)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_words(words: &str) -> anyhow::Result<Options> {
        let args: Vec<String> = words.split_whitespace().map(String::from).collect();
        parse(&args)
    }

    #[test]
    fn no_flags_compare_with_the_default_base_at_640x480() {
        assert_eq!(parse_words("").expect("parses"), Options::default());
    }

    #[test]
    fn every_flag_is_read() {
        let options =
            parse_words("--size 320x240 --only mesh --base v1.0 --mesh --csg").expect("parses");
        assert_eq!(
            options,
            Options {
                width: 320,
                height: 240,
                only: Some("mesh".to_string()),
                base: BaseRequest::Revision("v1.0".to_string()),
                mesh: true,
                csg: true,
                ..Options::default()
            }
        );
        assert_eq!(
            parse_words("--no-base").expect("parses").base,
            BaseRequest::Nothing
        );
    }

    #[test]
    fn bad_command_lines_say_what_is_wrong() {
        let message = |words| format!("{:#}", parse_words(words).unwrap_err());
        assert!(message("--size 320").contains("WxH"));
        assert!(message("--size ax240").contains("bad width"));
        assert!(message("--only").contains("--only needs"));
        assert!(message("--base").contains("--base needs"));
        assert!(message("--base HEAD --no-base").contains("contradict"));
        assert!(message("--no-base --base HEAD").contains("contradict"));
        assert!(message("--fast").contains("unknown bench option `--fast`"));
    }
}
