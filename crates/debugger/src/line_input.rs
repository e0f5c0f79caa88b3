//! A one-line text input for prompts (search, query, what-if values): text, a cursor, editing keys.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LineInput {
    text: String,
    /// In chars, 0 to the text's char count.
    cursor: usize,
}

/// What a key did to the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputOutcome {
    Edited,
    Submitted,
    Cancelled,
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

    /// The byte offset of char position `chars`.
    fn byte_at(&self, chars: usize) -> usize {
        self.text
            .char_indices()
            .nth(chars)
            .map_or(self.text.len(), |(i, _)| i)
    }

    /// Applies an editing key: characters insert at the cursor; Backspace and Delete
    /// remove; ←→ Home End move; Enter submits; Esc cancels. Anything else is ignored.
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
                    .intersects(KeyModifiers::CONTROL | KeyModifiers::ALT) =>
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
    fn typing_inserts_at_the_cursor_and_editing_keys_move_and_delete() {
        let mut input = LineInput::new("glas");
        assert_eq!(input.cursor(), 4);
        typed(&mut input, "s");
        assert_eq!(input.text(), "glass");
        input.handle(key(KeyCode::Home));
        typed(&mut input, "é ");
        assert_eq!((input.text(), input.cursor()), ("é glass", 2));
        input.handle(key(KeyCode::Left));
        input.handle(key(KeyCode::Backspace));
        assert_eq!((input.text(), input.cursor()), (" glass", 0));
        input.handle(key(KeyCode::Delete));
        assert_eq!(input.text(), "glass");
        input.handle(key(KeyCode::End));
        input.handle(key(KeyCode::Backspace));
        assert_eq!((input.text(), input.cursor()), ("glas", 4));
    }

    #[test]
    fn enter_submits_esc_cancels_and_edges_are_ignored() {
        let mut input = LineInput::new("");
        assert_eq!(input.handle(key(KeyCode::Backspace)), InputOutcome::Ignored);
        assert_eq!(input.handle(key(KeyCode::Left)), InputOutcome::Ignored);
        assert_eq!(input.handle(key(KeyCode::Delete)), InputOutcome::Ignored);
        assert_eq!(input.handle(key(KeyCode::F(1))), InputOutcome::Ignored);
        let control = KeyEvent::new(KeyCode::Char('a'), KeyModifiers::CONTROL);
        assert_eq!(input.handle(control), InputOutcome::Ignored);
        assert_eq!(input.handle(key(KeyCode::Enter)), InputOutcome::Submitted);
        assert_eq!(input.handle(key(KeyCode::Esc)), InputOutcome::Cancelled);
        let shifted = KeyEvent::new(KeyCode::Char('T'), KeyModifiers::SHIFT);
        assert_eq!(input.handle(shifted), InputOutcome::Edited);
        assert_eq!(input.text(), "T");
    }
}
