//! A one-line text input for prompts (search, query, what-if values): text, a cursor, editing
//! keys as in a shell (Ctrl-U, Ctrl-W), and optionally earlier entries recalled with ↑↓.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LineInput {
    text: String,
    /// In chars, 0 to the text's char count.
    cursor: usize,
    /// Earlier entries, oldest first, that ↑↓ bring back.
    history: Vec<String>,
    /// Which history entry shows, while recalling one; `None` while editing the draft.
    recalled: Option<usize>,
    /// What was typed before ↑ was first pressed, for ↓ to come back to.
    draft: String,
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
            history: Vec::new(),
            recalled: None,
            draft: String::new(),
        }
    }

    /// An empty input whose ↑↓ recall `history` (oldest first), newest first.
    pub fn with_history(history: &[String]) -> LineInput {
        LineInput {
            history: history.to_vec(),
            ..LineInput::new("")
        }
    }

    /// Replaces the text, the cursor at its end.
    fn set_text(&mut self, text: String) {
        self.cursor = text.chars().count();
        self.text = text;
    }

    /// ↑ (`older`) or ↓: the neighbouring history entry, or back to the draft after the newest.
    fn recall(&mut self, older: bool) -> InputOutcome {
        let last = match self.history.len().checked_sub(1) {
            Some(last) => last,
            None => return InputOutcome::Ignored,
        };
        let next = match (self.recalled, older) {
            (None, true) => Some(last),
            (None, false) => return InputOutcome::Ignored,
            (Some(0), true) => return InputOutcome::Ignored,
            (Some(at), true) => Some(at - 1),
            (Some(at), false) if at < last => Some(at + 1),
            (Some(_), false) => None,
        };
        if self.recalled.is_none() {
            self.draft = self.text.clone();
        }
        self.recalled = next;
        let text = match next {
            Some(at) => self.history[at].clone(),
            None => std::mem::take(&mut self.draft),
        };
        self.set_text(text);
        InputOutcome::Edited
    }

    /// Ctrl-W: the word before the cursor and the spaces after it, as a shell does.
    fn delete_word(&mut self) -> InputOutcome {
        let before: Vec<char> = self.text.chars().take(self.cursor).collect();
        let mut start = self.cursor;
        while start > 0 && before[start - 1].is_whitespace() {
            start -= 1;
        }
        while start > 0 && !before[start - 1].is_whitespace() {
            start -= 1;
        }
        if start == self.cursor {
            return InputOutcome::Ignored;
        }
        let (from, to) = (self.byte_at(start), self.byte_at(self.cursor));
        self.text.replace_range(from..to, "");
        self.cursor = start;
        InputOutcome::Edited
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
    /// remove; Ctrl-U clears to the start of the line and Ctrl-W deletes the word before the
    /// cursor; ←→ Home End move; ↑↓ recall the history; Enter submits; Esc cancels.
    /// Anything else is ignored.
    pub fn handle(&mut self, key: KeyEvent) -> InputOutcome {
        if key.kind == KeyEventKind::Release {
            return InputOutcome::Ignored;
        }
        let length = self.text.chars().count();
        let control = key.modifiers.contains(KeyModifiers::CONTROL);
        match key.code {
            KeyCode::Enter => InputOutcome::Submitted,
            KeyCode::Esc => InputOutcome::Cancelled,
            KeyCode::Up => self.recall(true),
            KeyCode::Down => self.recall(false),
            KeyCode::Char('u' | 'U') if control => {
                if self.cursor == 0 {
                    return InputOutcome::Ignored;
                }
                let at = self.byte_at(self.cursor);
                self.text.replace_range(..at, "");
                self.cursor = 0;
                InputOutcome::Edited
            }
            KeyCode::Char('w' | 'W') if control => self.delete_word(),
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

    fn control(c: char) -> KeyEvent {
        KeyEvent::new(KeyCode::Char(c), KeyModifiers::CONTROL)
    }

    #[test]
    fn control_u_clears_to_the_start_and_control_w_deletes_the_word_before_the_cursor() {
        let mut input = LineInput::new("depth >= 3 and tir");
        assert_eq!(input.handle(control('w')), InputOutcome::Edited);
        assert_eq!((input.text(), input.cursor()), ("depth >= 3 and ", 15));
        // The spaces before the cursor go with the word before them.
        input.handle(control('w'));
        assert_eq!((input.text(), input.cursor()), ("depth >= 3 ", 11));
        // In the middle of the line only what is before the cursor goes.
        input.handle(key(KeyCode::Left));
        input.handle(key(KeyCode::Left));
        input.handle(control('w'));
        assert_eq!((input.text(), input.cursor()), ("depth 3 ", 6));
        input.handle(control('u'));
        assert_eq!((input.text(), input.cursor()), ("3 ", 0));
        assert_eq!(input.handle(control('u')), InputOutcome::Ignored);
        assert_eq!(input.handle(control('w')), InputOutcome::Ignored);
        let mut accented = LineInput::new("hit(\"é\") é");
        accented.handle(control('w'));
        assert_eq!(accented.text(), "hit(\"é\") ");
    }

    #[test]
    fn up_and_down_recall_earlier_entries_and_come_back_to_the_draft() {
        let history = ["tir".to_string(), "depth >= 3".to_string()];
        let mut input = LineInput::with_history(&history);
        assert_eq!(input.text(), "", "the prompt opens empty");
        typed(&mut input, "hit");
        assert_eq!(input.handle(key(KeyCode::Down)), InputOutcome::Ignored);
        input.handle(key(KeyCode::Up));
        assert_eq!((input.text(), input.cursor()), ("depth >= 3", 10));
        input.handle(key(KeyCode::Up));
        assert_eq!(input.text(), "tir");
        assert_eq!(input.handle(key(KeyCode::Up)), InputOutcome::Ignored);
        assert_eq!(input.text(), "tir");
        input.handle(key(KeyCode::Down));
        assert_eq!(input.text(), "depth >= 3");
        input.handle(key(KeyCode::Down));
        assert_eq!((input.text(), input.cursor()), ("hit", 3));
        let mut empty = LineInput::with_history(&[]);
        assert_eq!(empty.handle(key(KeyCode::Up)), InputOutcome::Ignored);
    }
}
