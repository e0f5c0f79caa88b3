//! A one-line text input for prompts (search, query, what-if values): text, a cursor, editing keys.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

/// The text being typed and where the cursor is (in chars, not bytes).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LineInput {
    text: String,
    cursor: usize,
}

/// What a key did to the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputOutcome {
    /// The text or the cursor changed.
    Edited,
    /// Enter: the text is final.
    Submitted,
    /// Esc: the prompt is abandoned.
    Cancelled,
    /// A key the input does not use.
    Ignored,
}

impl LineInput {
    /// An input holding `initial`, the cursor at its end.
    pub fn new(initial: &str) -> LineInput {
        LineInput {
            text: initial.to_string(),
            cursor: initial.chars().count(),
        }
    }

    pub fn text(&self) -> &str {
        &self.text
    }

    /// The cursor's position in chars, for drawing it.
    pub fn cursor(&self) -> usize {
        self.cursor
    }

    /// The byte offset of char `index` (the end of the text past the last char).
    fn byte_at(&self, index: usize) -> usize {
        self.text
            .char_indices()
            .nth(index)
            .map_or(self.text.len(), |(at, _)| at)
    }

    /// Applies one key: printable chars insert at the cursor; Backspace, Delete, ←, →,
    /// Home, End edit and move; Enter submits and Esc cancels.
    pub fn handle(&mut self, key: KeyEvent) -> InputOutcome {
        if key.kind == KeyEventKind::Release {
            return InputOutcome::Ignored;
        }
        let length = self.text.chars().count();
        match key.code {
            KeyCode::Enter => InputOutcome::Submitted,
            KeyCode::Esc => InputOutcome::Cancelled,
            KeyCode::Char(c)
                if !key
                    .modifiers
                    .intersects(KeyModifiers::CONTROL | KeyModifiers::ALT)
                    && !c.is_control() =>
            {
                let at = self.byte_at(self.cursor);
                self.text.insert(at, c);
                self.cursor += 1;
                InputOutcome::Edited
            }
            KeyCode::Backspace if self.cursor > 0 => {
                let at = self.byte_at(self.cursor - 1);
                self.text.remove(at);
                self.cursor -= 1;
                InputOutcome::Edited
            }
            KeyCode::Delete if self.cursor < length => {
                let at = self.byte_at(self.cursor);
                self.text.remove(at);
                InputOutcome::Edited
            }
            KeyCode::Left if self.cursor > 0 => {
                self.cursor -= 1;
                InputOutcome::Edited
            }
            KeyCode::Right if self.cursor < length => {
                self.cursor += 1;
                InputOutcome::Edited
            }
            KeyCode::Home => {
                self.cursor = 0;
                InputOutcome::Edited
            }
            KeyCode::End => {
                self.cursor = length;
                InputOutcome::Edited
            }
            // At either end, or a key with no meaning here: nothing changes.
            _ => InputOutcome::Ignored,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    fn typed(input: &mut LineInput, text: &str) {
        for c in text.chars() {
            assert_eq!(input.handle(key(KeyCode::Char(c))), InputOutcome::Edited);
        }
    }

    #[test]
    fn typing_inserts_at_the_cursor_and_moves_it() {
        let mut input = LineInput::new("1.5");
        assert_eq!(input.cursor(), 3);
        input.handle(key(KeyCode::Home));
        typed(&mut input, "2");
        assert_eq!(input.text(), "21.5");
        assert_eq!(input.cursor(), 1);
        input.handle(key(KeyCode::End));
        typed(&mut input, "é0");
        assert_eq!(input.text(), "21.5é0");
        assert_eq!(input.cursor(), 6);
    }

    #[test]
    fn backspace_and_delete_remove_around_the_cursor_even_in_multibyte_text() {
        let mut input = LineInput::new("aéb");
        input.handle(key(KeyCode::Left));
        assert_eq!(input.handle(key(KeyCode::Backspace)), InputOutcome::Edited);
        assert_eq!(input.text(), "ab");
        assert_eq!(input.cursor(), 1);
        assert_eq!(input.handle(key(KeyCode::Delete)), InputOutcome::Edited);
        assert_eq!(input.text(), "a");
        assert_eq!(input.handle(key(KeyCode::Delete)), InputOutcome::Ignored);
        input.handle(key(KeyCode::Home));
        assert_eq!(input.handle(key(KeyCode::Backspace)), InputOutcome::Ignored);
        assert_eq!(input.handle(key(KeyCode::Left)), InputOutcome::Ignored);
        assert_eq!(input.text(), "a");
    }

    #[test]
    fn enter_submits_esc_cancels_and_control_keys_are_ignored() {
        let mut input = LineInput::new("tir");
        assert_eq!(input.handle(key(KeyCode::Enter)), InputOutcome::Submitted);
        assert_eq!(input.handle(key(KeyCode::Esc)), InputOutcome::Cancelled);
        let control_a = KeyEvent::new(KeyCode::Char('a'), KeyModifiers::CONTROL);
        assert_eq!(input.handle(control_a), InputOutcome::Ignored);
        assert_eq!(input.handle(key(KeyCode::F(2))), InputOutcome::Ignored);
        assert_eq!(input.text(), "tir");
    }
}
