//! Animations: an environment that films itself (a scene after every step) and a GIF of the
//! frames, each a top view of the scene under a caption.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use seads_embodiment::{Environment, Filmed, Scene, SkillPolicy, execute_skill};

use crate::draw::{draw_scene, plot_err, register_font};
use crate::{Result, StudyError};

/// One short clip per skill: each executed from `starts` of the coverage initialisations of `env`
/// (seeds `seed`, `seed + 1`, …), a frame per step under "skill k · start i · step t", the last
/// frame of each clip shown twice more.
pub fn skill_clips(
    env: Box<dyn Environment>,
    policy: &dyn SkillPolicy,
    starts: u64,
    seed: u64,
) -> Result<Vec<(Scene, String)>> {
    let mut filmed = Filmed::new(env);
    let mut frames = Vec::new();
    for skill in 0..policy.num_skills() {
        for start in 0..starts {
            filmed.seed(seed + start);
            filmed
                .reset()
                .map_err(|e| StudyError::file("resetting the environment", e))?;
            filmed.take_frames(); // from the board just drawn
            let run = execute_skill(&mut filmed, policy, skill)
                .map_err(|e| StudyError::file("executing a skill", e))?;
            let caption = |t: usize| format!("skill {skill} · start {} · step {t}", start + 1);
            for (t, scene) in filmed.take_frames().into_iter().enumerate() {
                frames.push((scene, caption(t)));
            }
            let moved = if run.outcome.moved() {
                "a move"
            } else {
                "no move"
            };
            let end = frames[frames.len() - 1].0.clone();
            for _ in 0..2 {
                frames.push((
                    end.clone(),
                    format!("skill {skill} · start {}: {moved}", start + 1),
                ));
            }
        }
    }
    Ok(frames)
}

/// Frame size of the animations, pixels.
const SIZE: (u32, u32) = (480, 520);
/// The most frames one animation holds (a longer one keeps its first ones and says so).
pub const MAX_FRAMES: usize = 2000;

/// Writes `frames` (a scene and its caption each) as an animated GIF to `out`, each shown
/// `delay_ms` and the last one `hold_ms`, atomically (a temporary file beside it, then renamed;
/// removed again if anything fails). Returns how many of the frames it holds: at most
/// [`MAX_FRAMES`], the first ones.
pub fn write_gif(
    frames: &[(Scene, String)],
    delay_ms: u32,
    hold_ms: u32,
    out: &Path,
) -> Result<usize> {
    if frames.is_empty() {
        return Err(StudyError::invalid("an animation needs at least one frame"));
    }
    register_font();
    let tmp = out.with_extension(format!("gif.tmp-{}", std::process::id()));
    let written = (|| -> Result<()> {
        let mut shown: Vec<(&(Scene, String), u32)> = frames
            .iter()
            .take(MAX_FRAMES)
            .map(|f| (f, delay_ms))
            .collect();
        if let Some(last) = shown.last_mut() {
            last.1 = hold_ms.max(delay_ms);
        }
        // plotters' GIF backend takes one delay for all frames: a held frame repeats.
        let root = BitMapBackend::gif(&tmp, SIZE, delay_ms.max(10))
            .map_err(|e| StudyError::Plot(e.to_string()))?
            .into_drawing_area();
        for ((scene, caption), ms) in shown {
            for _ in 0..(ms / delay_ms.max(10)).max(1) {
                draw_frame(&root, scene, caption)?;
                root.present().map_err(plot_err)?;
            }
        }
        Ok(())
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    let sync = std::fs::File::open(&tmp).and_then(|f| f.sync_all());
    if let Err(e) = sync.and_then(|()| std::fs::rename(&tmp, out)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(StudyError::file(format!("writing {}", out.display()), e));
    }
    Ok(frames.len().min(MAX_FRAMES))
}

fn draw_frame<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scene: &Scene,
    caption: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    area.fill(&WHITE).map_err(plot_err)?;
    draw_scene(area, scene, caption, 16, true)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three frames of a LightsOutCursor board after a reset.
    fn frames() -> Vec<(Scene, String)> {
        let mut env = seads_embodiment::make_env("lightsout-cursor", &Default::default()).unwrap();
        env.seed(1);
        env.reset().unwrap();
        vec![(env.scene(), "a caption".to_owned()); 3]
    }

    /// A GIF whose last step fails (the rename into place: a folder with a file in it stands
    /// where the GIF goes) leaves no temporary file behind (issue 82 found `*.gif.tmp-PID` files
    /// left); one that can be written holds every frame, and says how many.
    #[test]
    fn a_failed_write_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let blocked = dir.path().join("blocked.gif");
        std::fs::create_dir(&blocked).unwrap();
        std::fs::write(blocked.join("keep"), "").unwrap();
        assert!(write_gif(&frames(), 150, 150, &blocked).is_err());
        let names = || -> Vec<String> {
            let mut names: Vec<String> = std::fs::read_dir(dir.path())
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            names.sort();
            names
        };
        assert_eq!(names(), ["blocked.gif"]);
        let out = dir.path().join("x.gif");
        assert_eq!(write_gif(&frames(), 150, 150, &out).unwrap(), 3);
        assert_eq!(names(), ["blocked.gif", "x.gif"]);
    }
}
