//! What a player's frame asks of the driver: the dispatches and draw calls of its last
//! record (with a `simulate` before it) and of its draws since
//! ([`Player::recorded_commands`]). Instances of one preset share a batch's dispatches
//! and draws, so these stay the same from one instance to a batch full.

use std::sync::atomic::{AtomicU32, Ordering};

use crate::gpu::commands::{self, CommandCounts};
use crate::runtime::Player;

/// A player's counts of its frame's commands.
#[derive(Debug, Default)]
pub(crate) struct FrameCommands {
    /// The last record's (and a `simulate` before it), with the compute resolves since.
    recorded: CommandCounts,
    /// The draws since the last record (`draw` takes `&self`).
    drawn: AtomicU32,
}

impl FrameCommands {
    /// Starts counting a record (or a `simulate`); `continues`: a `simulate` of the same
    /// frame was counted before it.
    pub fn begin(&mut self, continues: bool) -> CommandCounts {
        if !continues {
            self.recorded = CommandCounts::default();
        }
        self.drawn.store(0, Ordering::Relaxed);
        commands::recorded()
    }

    /// Adds what was recorded since `start` (a reading of [`commands::recorded`]).
    pub fn add_since(&mut self, start: CommandCounts) {
        self.recorded = self.recorded + (commands::recorded() - start);
    }

    /// Adds the draws recorded since `start` (a reading of [`commands::recorded`]).
    pub fn add_draws_since(&self, start: CommandCounts) {
        let drawn = (commands::recorded() - start).draws;
        self.drawn.fetch_add(drawn, Ordering::Relaxed);
    }
}

impl Player {
    /// The dispatches and draw calls this player recorded for its frame: the last
    /// [`Player::record`] (and a [`Player::simulate`] of the same frame), every draw since
    /// and the heat haze applied ([`Player::apply_haze`]). Instances of one preset share
    /// them: a batch of instances records the same commands as one instance (a host's
    /// profiler can show them as its "draw calls").
    pub fn recorded_commands(&self) -> CommandCounts {
        let mut counts = self.commands.recorded;
        counts.draws += self.commands.drawn.load(Ordering::Relaxed);
        counts
    }
}
