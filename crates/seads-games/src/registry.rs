//! The games by name: one list (`GAMES`, in the crate root) that the command line, configs,
//! environments, reports and the Python package read. A new game is a type implementing
//! [`BoardGame`] with a [`GameEntry`], listed once there; nothing outside this crate names a
//! concrete game.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::{BoardGame, GameError};

/// What the registry knows of a game: its names, sizes and how to build it.
#[derive(Debug)]
pub struct GameEntry {
    /// Lower-case name on the command line and in configs (`lightsout`).
    pub name: &'static str,
    /// Name in CamelCase, for Gymnasium ids (`LightsOut`).
    pub title: &'static str,
    /// One line for listings.
    pub description: &'static str,
    /// Board side when none is given.
    pub default_size: usize,
    /// Builds the game of a side length (an error for sizes the game does not have).
    pub build: fn(usize) -> Result<Box<dyn BoardGame>, GameError>,
}

/// A registered game, as named on the command line and in configs (serialised as its name).
#[derive(Clone, Copy)]
pub struct GameKind(&'static GameEntry);

impl GameKind {
    /// Every registered game, in listing order.
    pub fn all() -> impl Iterator<Item = GameKind> {
        crate::GAMES.iter().map(|&entry| GameKind(entry))
    }

    /// The game of `entry` (a game's own [`BoardGame::kind`]).
    pub const fn of(entry: &'static GameEntry) -> Self {
        GameKind(entry)
    }

    /// The registered game called `name` (any case).
    ///
    /// ```
    /// use seads_games::GameKind;
    /// let game = GameKind::named("LightsOut")?;
    /// assert_eq!((game.name(), game.default_size()), ("lightsout", 5));
    /// assert!(GameKind::named("chess").unwrap_err().to_string().contains("lightsout, tileswap"));
    /// # Ok::<(), seads_games::GameError>(())
    /// ```
    pub fn named(name: &str) -> Result<Self, GameError> {
        let lower = name.to_ascii_lowercase();
        Self::all()
            .find(|g| g.name() == lower)
            .ok_or_else(|| GameError::UnknownGame {
                name: name.to_owned(),
                valid: Self::all()
                    .map(GameKind::name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The lower-case name used on the command line.
    pub fn name(self) -> &'static str {
        self.0.name
    }

    /// The name in CamelCase (`LightsOut`).
    pub fn title(self) -> &'static str {
        self.0.title
    }

    /// One line for listings.
    pub fn description(self) -> &'static str {
        self.0.description
    }

    /// The default board size (5 for LightsOut, 3 for TileSwap and the sliding puzzle; SPEC §1).
    pub fn default_size(self) -> usize {
        self.0.default_size
    }

    /// Builds the game of this kind and size.
    pub fn build(self, size: usize) -> Result<Box<dyn BoardGame>, GameError> {
        (self.0.build)(size)
    }
}

impl PartialEq for GameKind {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for GameKind {}

impl PartialOrd for GameKind {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for GameKind {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.name().cmp(other.name())
    }
}

impl std::hash::Hash for GameKind {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.name().hash(state);
    }
}

impl std::fmt::Debug for GameKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Display for GameKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for GameKind {
    type Err = GameError;
    fn from_str(s: &str) -> Result<Self, GameError> {
        Self::named(s)
    }
}

impl Serialize for GameKind {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for GameKind {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = String::deserialize(deserializer)?;
        Self::named(&name).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each entry builds its own game at its default size, and names are unique.
    #[test]
    fn every_entry_builds_a_game_that_names_itself() {
        let mut names = std::collections::BTreeSet::new();
        for kind in GameKind::all() {
            assert!(names.insert(kind.name()), "{kind} listed twice");
            let game = kind.build(kind.default_size()).unwrap();
            assert_eq!(game.kind(), kind);
            assert_eq!(game.size(), kind.default_size());
            assert_eq!(GameKind::named(kind.title()).unwrap(), kind);
        }
        let json = serde_json::to_string(&GameKind::named("tileswap").unwrap()).unwrap();
        assert_eq!(json, "\"tileswap\"");
        assert!(serde_json::from_str::<GameKind>("\"chess\"").is_err());
    }
}
