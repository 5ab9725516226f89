//! Gestures as commands: a table of held gestures and the commands they trigger (the
//! paper's "gestures act as commands"), each once per hold: a scene file's scene actions, or
//! an application's own rows (the viewer's, from the input configuration's `actions`).

use crate::gesture::{Event, EventKind, GestureSet};
use crate::scene::{SceneAction, SceneCommand};
use crate::{Error, Result};

/// One row of a command table: a gesture, how long it is held, and its command.
pub trait CommandRow {
    /// The command it triggers.
    type Command: Copy;
    /// The gesture's name.
    fn gesture(&self) -> &str;
    /// Seconds it must be held.
    fn hold_s(&self) -> f32;
    /// The command.
    fn command(&self) -> Self::Command;
}

impl CommandRow for SceneAction {
    type Command = SceneCommand;
    fn gesture(&self) -> &str {
        &self.gesture
    }
    fn hold_s(&self) -> f32 {
        self.hold_s
    }
    fn command(&self) -> SceneCommand {
        self.action
    }
}

/// Watches the gesture events and fires each row's action once, when its gesture has been
/// held for the row's `hold_s` since it started. A gesture released and made again fires again.
#[derive(Clone, Debug)]
pub struct CommandTable<R> {
    rows: Vec<R>,
    /// Each row's gesture, as its index in the set (resolved once from its name).
    gestures: Vec<usize>,
    /// The held gesture's first row, since when, and which rows have fired during this hold
    /// (bit per row); `None` while no gesture with a row is held.
    held: Option<(usize, f64, u64)>,
}

impl<R: CommandRow + Clone> CommandTable<R> {
    /// The table of `actions` over `set`'s gestures.
    ///
    /// # Errors
    /// [`Error::Config`] naming a row whose gesture `set` does not define, or a table of
    /// more than 64 rows.
    pub fn new(actions: &[R], set: &GestureSet) -> Result<Self> {
        if actions.len() > 64 {
            return Err(Error::Config(format!("actions: {} rows (at most 64)", actions.len())));
        }
        let gestures = actions
            .iter()
            .map(|a| {
                set.gestures()
                    .iter()
                    .position(|g| g.name() == a.gesture())
                    .ok_or_else(|| Error::Config(format!("actions: {:?} is not a gesture of the definitions in use", a.gesture())))
            })
            .collect::<Result<_>>()?;
        Ok(Self { rows: actions.to_vec(), gestures, held: None })
    }

    /// The same rows over another set (gestures added or reordered), nothing held.
    ///
    /// # Errors
    /// As [`Self::new`]: a row whose gesture `set` does not define.
    pub fn rebind(&self, set: &GestureSet) -> Result<Self> {
        Self::new(&self.rows, set)
    }

    /// Takes one update's gesture `events` at `time_s` and returns the action due now, if
    /// any (the first due row; another due at the same time follows on the next update).
    /// Allocates nothing.
    pub fn update<'a>(&mut self, time_s: f64, events: impl IntoIterator<Item = Event<'a>>) -> Option<R::Command> {
        for e in events {
            self.held = match e.event {
                EventKind::Start => self.gestures.iter().position(|&g| g == e.index).map(|row| (row, e.t, 0)),
                EventKind::End => None,
            };
        }
        let (first, since, fired) = self.held.as_mut()?;
        let gesture = self.gestures[*first];
        let (i, row) = self
            .rows
            .iter()
            .enumerate()
            .find(|&(i, r)| self.gestures[i] == gesture && *fired & (1 << i) == 0 && time_s - *since >= f64::from(r.hold_s()))?;
        *fired |= 1 << i;
        Some(row.command())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row whose command is a number.
    #[derive(Clone, Debug)]
    struct Row(&'static str, f32, u8);

    impl CommandRow for Row {
        type Command = u8;
        fn gesture(&self) -> &str {
            self.0
        }
        fn hold_s(&self) -> f32 {
            self.1
        }
        fn command(&self) -> u8 {
            self.2
        }
    }

    fn table(rows: &[Row]) -> CommandTable<Row> {
        CommandTable::new(rows, &GestureSet::builtin()).unwrap()
    }

    fn event(t: f64, event: EventKind, gesture: &str) -> Event<'_> {
        let index = GestureSet::builtin().gestures().iter().position(|g| g.name() == gesture).expect("a built-in gesture");
        Event { t, event, gesture, index }
    }

    fn start(t: f64, gesture: &str) -> [Event<'_>; 1] {
        [event(t, EventKind::Start, gesture)]
    }

    fn end(t: f64, gesture: &str) -> [Event<'_>; 1] {
        [event(t, EventKind::End, gesture)]
    }

    #[test]
    fn fires_once_per_hold_after_its_time() {
        let mut t = table(&[Row("thumbs_up", 0.5, 1)]);
        assert_eq!(t.update(1.0, start(1.0, "thumbs_up")), None);
        assert_eq!(t.update(1.49, []), None);
        assert_eq!(t.update(1.5, []), Some(1));
        assert_eq!(t.update(2.5, []), None, "once per hold");
        assert_eq!(t.update(2.6, end(2.6, "thumbs_up")), None);
        assert_eq!(t.update(3.0, start(3.0, "thumbs_up")), None);
        assert_eq!(t.update(3.5, []), Some(1), "a new hold fires again");
    }

    #[test]
    fn another_gesture_restarts_the_hold() {
        let mut t = table(&[Row("rock", 0.8, 3)]);
        assert_eq!(t.update(0.0, start(0.0, "rock")), None);
        let switch = [event(0.5, EventKind::End, "rock"), event(0.5, EventKind::Start, "fist")];
        assert_eq!(t.update(0.5, switch), None);
        assert_eq!(t.update(1.0, []), None, "fist has no row");
        assert_eq!(t.update(1.1, start(1.1, "rock")), None);
        assert_eq!(t.update(1.8, []), None, "0.7 s of this hold");
        assert_eq!(t.update(1.95, []), Some(3));
    }

    #[test]
    fn rows_of_one_gesture_fire_in_turn() {
        let mut t = table(&[Row("victory", 0.0, 2), Row("point", 0.0, 1), Row("victory", 1.0, 3)]);
        assert_eq!(t.update(0.0, start(0.0, "victory")), Some(2));
        assert_eq!(t.update(0.5, []), None);
        assert_eq!(t.update(1.0, []), Some(3));
        assert_eq!(t.update(5.0, []), None);
    }

    #[test]
    fn an_unknown_gesture_is_a_config_error_naming_it() {
        let e = CommandTable::new(&[Row("wave", 0.5, 1)], &GestureSet::builtin()).unwrap_err().to_string();
        assert!(e.contains("\"wave\""), "{e}");
    }
}
