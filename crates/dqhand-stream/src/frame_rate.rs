//! The engine's frame rate as the hello and the frames report it: frames counted over the last
//! second or so, on whatever clock the transport steps by (a socket's `Instant`, the page's
//! timer).

/// Frames per second over the last second or so.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameRate {
    since: f64,
    count: u32,
    fps: f32,
}

impl FrameRate {
    /// Counts a frame at `now` (s, any origin, not decreasing); returns the latest rate.
    pub fn tick(&mut self, now: f64) -> f32 {
        self.count += 1;
        let elapsed = now - self.since;
        if elapsed >= 1.0 {
            self.fps = self.count as f32 / elapsed as f32;
            (self.since, self.count) = (now, 0);
        }
        self.fps
    }
}

#[cfg(test)]
mod tests {
    use super::FrameRate;

    #[test]
    fn sixty_frames_a_second_read_as_sixty() {
        let mut rate = FrameRate::default();
        let mut fps = 0.0;
        for i in 1..=180 {
            fps = rate.tick(f64::from(i) / 60.0);
        }
        assert!((fps - 60.0).abs() < 0.5, "{fps}");
    }
}
