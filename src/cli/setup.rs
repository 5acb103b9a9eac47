//! What a command evaluates of a file: its options (clip, modes, layers) made one [`Setup`], and that made the
//! evaluation. Every command that evaluates a file builds it here.

use anyhow::Context;
use clap::Args;

use super::layers::LayerArgs;
use super::options::{choice, clip_index, parse_bone_mode};
use crate::eval::{Evaluation, Setup};
use crate::model::{Choice, InheritMode, ModeChoice, Modes, Rig};

/// What is evaluated: which clip, which inheritance modes, which layers. Every command that evaluates one file
/// makes its [`Setup`] here ([`EvalArgs::setup`]).
#[derive(Clone, Debug, Default, Args)]
pub struct EvalArgs {
    /// The animation, by name or index (default: `inspect` the first, `scan` every one).
    #[arg(long, value_name = "NAME|INDEX")]
    pub anim: Option<String>,
    /// Evaluate every bone with this mode instead of the one the file declares.
    #[arg(long, value_name = "MODE", value_parser = choice::<ModeChoice>(), default_value = ModeChoice::Declared.id())]
    pub inherit: ModeChoice,
    /// Then give one bone its own mode (repeatable).
    #[arg(long = "inherit-bone", value_name = "NAME=MODE", value_parser = parse_bone_mode)]
    pub inherit_bone: Vec<(String, InheritMode)>,
    #[command(flatten)]
    pub layers: LayerArgs,
}

impl EvalArgs {
    /// The setup these options ask of `rig`: the clip `--anim` names (else the first), the file's modes or
    /// `--inherit`'s with the `--inherit-bone` overrides, and the layers.
    pub fn setup(&self, rig: &Rig) -> anyhow::Result<Setup> {
        let clip = match &self.anim {
            None => Setup::declared(rig).clip,
            Some(name) => Some(clip_index(rig, "--anim", name)?),
        };
        let mut modes = Modes::all(self.inherit);
        for (name, mode) in &self.inherit_bone {
            let bone = rig.skeleton.find(name).with_context(|| format!("--inherit-bone: no bone named `{name}`"))?;
            modes.set(&rig.skeleton, bone, ModeChoice::Mode(*mode));
        }
        Ok(Setup { clip, modes, layers: self.layers.layers(rig)?, ..Setup::default() })
    }

    /// The clips a whole-file command (`scan`, `storage`) visits: the one `--anim` names, else every clip (the
    /// rest pose of a file without any).
    pub fn clips(&self, rig: &Rig) -> anyhow::Result<Vec<Option<usize>>> {
        Ok(match &self.anim {
            Some(name) => vec![Some(clip_index(rig, "--anim", name)?)],
            None if rig.clips.is_empty() => vec![None],
            None => (0..rig.clips.len()).map(Some).collect(),
        })
    }
}

/// `setup` of `rig`: the one evaluation every command makes of its options.
pub fn evaluation<'a>(rig: &'a Rig, setup: &Setup) -> anyhow::Result<Evaluation<'a>> {
    Ok(Evaluation::of(rig, setup)?)
}
