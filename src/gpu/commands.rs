//! Counts of the GPU work commands recorded on this thread: dispatches and draws. Every
//! dispatch and draw of the library goes through [`CountedCompute`] or [`CountedRender`],
//! so a player can say what one of its frames asks of the driver
//! ([`Player::recorded_commands`](crate::Player::recorded_commands)), and a test can hold
//! the runtime's batching to a constant number of commands per batch.

use std::cell::Cell;

/// Dispatches and draw calls recorded (each indirect one counts as one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CommandCounts {
    /// Compute dispatches.
    pub dispatches: u32,
    /// Draw calls.
    pub draws: u32,
}

impl std::ops::Add for CommandCounts {
    type Output = Self;

    fn add(self, o: Self) -> Self {
        Self {
            dispatches: self.dispatches + o.dispatches,
            draws: self.draws + o.draws,
        }
    }
}

impl std::ops::Sub for CommandCounts {
    type Output = Self;

    /// What was recorded between two readings of the count (saturating).
    fn sub(self, o: Self) -> Self {
        Self {
            dispatches: self.dispatches.saturating_sub(o.dispatches),
            draws: self.draws.saturating_sub(o.draws),
        }
    }
}

thread_local! {
    static RECORDED: Cell<CommandCounts> = const {
        Cell::new(CommandCounts { dispatches: 0, draws: 0 })
    };
}

/// Every command recorded on this thread so far (wrapping): subtract two readings.
pub fn recorded() -> CommandCounts {
    RECORDED.with(Cell::get)
}

fn count(dispatches: u32, draws: u32) {
    RECORDED.with(|c| {
        let v = c.get();
        c.set(CommandCounts {
            dispatches: v.dispatches.wrapping_add(dispatches),
            draws: v.draws.wrapping_add(draws),
        });
    });
}

/// A compute pass's dispatches, counted.
pub trait CountedCompute {
    /// `dispatch_workgroups`, counted.
    fn dispatch(&mut self, x: u32, y: u32, z: u32);
    /// `dispatch_workgroups_indirect`, counted.
    fn dispatch_indirect(&mut self, args: &wgpu::Buffer, offset: u64);
}

impl CountedCompute for wgpu::ComputePass<'_> {
    fn dispatch(&mut self, x: u32, y: u32, z: u32) {
        count(1, 0);
        self.dispatch_workgroups(x, y, z);
    }

    fn dispatch_indirect(&mut self, args: &wgpu::Buffer, offset: u64) {
        count(1, 0);
        self.dispatch_workgroups_indirect(args, offset);
    }
}

/// A render pass's draws, counted.
pub trait CountedRender {
    /// `draw`, counted.
    fn counted_draw(&mut self, vertices: std::ops::Range<u32>, instances: std::ops::Range<u32>);
    /// `draw_indexed` (base vertex 0), counted.
    fn counted_draw_indexed(
        &mut self,
        indices: std::ops::Range<u32>,
        instances: std::ops::Range<u32>,
    );
    /// `draw_indirect`, counted.
    fn counted_draw_indirect(&mut self, args: &wgpu::Buffer, offset: u64);
}

impl CountedRender for wgpu::RenderPass<'_> {
    fn counted_draw(&mut self, vertices: std::ops::Range<u32>, instances: std::ops::Range<u32>) {
        count(0, 1);
        self.draw(vertices, instances);
    }

    fn counted_draw_indexed(
        &mut self,
        indices: std::ops::Range<u32>,
        instances: std::ops::Range<u32>,
    ) {
        count(0, 1);
        self.draw_indexed(indices, 0, instances);
    }

    fn counted_draw_indirect(&mut self, args: &wgpu::Buffer, offset: u64) {
        count(0, 1);
        self.draw_indirect(args, offset);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_subtract_to_what_was_counted_between() {
        let before = recorded();
        count(2, 0);
        count(0, 3);
        assert_eq!(
            recorded() - before,
            CommandCounts {
                dispatches: 2,
                draws: 3
            }
        );
    }
}
