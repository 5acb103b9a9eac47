//! bonescope for Python: the library's evaluation as numpy arrays, and `scan`, `explain`, `diff` and `bake`
//! returning what the command line prints as JSON, as plain dicts and lists. Work runs without the GIL on the
//! library's threads; a long scan stops at Ctrl+C.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use numpy::PyArray;
use numpy::ndarray::{Array, IxDyn};
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use bonescope_core::analysis::report::FileReport;
use bonescope_core::analysis::{ScanOptions, Tolerances, sample};
use bonescope_core::bake::{Engine, Plan, Strategy, bake_file, in_metres};
use bonescope_core::diff::{Align, Clips, FileSide, chosen_clips, diff_files};
use bonescope_core::eval::layers::RotationInterpolation;
use bonescope_core::eval::{Evaluation, Layers, Setup};
use bonescope_core::explain::{Costs, Question, Report, explain, scan_clip};
use bonescope_core::import;
use bonescope_core::model::{Choice, ModeChoice, Modes, Unit, UpAxis};

pyo3::create_exception!(
    bonescope,
    Error,
    PyException,
    "What bonescope cannot read or do: one line naming the file and the place, as the command line says it."
);

/// The library's message as this module's exception.
fn error(message: impl std::fmt::Display) -> PyErr {
    Error::new_err(message.to_string())
}

/// A value serialised as the command line's JSON, read back by Python's `json` module: the same keys, the same
/// numbers.
fn json_value(py: Python<'_>, value: &impl serde::Serialize) -> PyResult<Py<PyAny>> {
    let text = serde_json::to_string(value).map_err(error)?;
    Ok(py.import("json")?.call_method1("loads", (text,))?.unbind())
}

/// `work` on another thread while this one waits without the GIL, checking for Ctrl+C every 50 ms: on
/// KeyboardInterrupt `cancel` is set, the work is waited for (it stops at its next check) and the interrupt raised.
fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce(&AtomicBool) -> Option<T> + Send) -> PyResult<T> {
    let cancel = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let running = scope.spawn(|| work(&cancel));
        while !running.is_finished() {
            py.detach(|| std::thread::sleep(Duration::from_millis(50)));
            if let Err(interrupt) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                let _ = py.detach(|| running.join());
                return Err(interrupt);
            }
        }
        match running.join() {
            Ok(Some(done)) => Ok(done),
            Ok(None) => Err(error("interrupted")),
            Err(_) => Err(error("bonescope failed inside (a bug): please report the file")),
        }
    })
}

/// A path, or anything `os.fspath` takes.
fn path_of(path: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    path.extract::<PathBuf>()
}

/// Loads an animation file (glTF `.gltf`/`.glb`, FBX, BVH, USD `.usda`/`.usdc`/`.usdz`; recognised by content).
///
/// `max_memory` is the most memory the file may take, in bytes or as text (`"8GiB"`, `"512M"`); a file estimated to
/// need more is refused. Raises `bonescope.Error` with the command line's one-line message.
#[pyfunction]
#[pyo3(signature = (path, *, max_memory = None))]
fn load(py: Python<'_>, path: &Bound<'_, PyAny>, max_memory: Option<&Bound<'_, PyAny>>) -> PyResult<Rig> {
    let path = path_of(path)?;
    let limit = match max_memory {
        None => None,
        Some(size) if size.is_instance_of::<PyString>() => {
            Some(import::budget::parse_size(&size.extract::<String>()?).map_err(error)?)
        }
        Some(size) => Some(size.extract::<u64>()?),
    };
    let loaded = py.detach(|| {
        // The budget is the process's: loads from several Python threads take turns, so none reads another's.
        let _turn = LOADING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let before = import::budget::explicit_limit();
        import::budget::set_limit(limit.or(before));
        let loaded = import::load(&path);
        import::budget::set_limit(before);
        loaded
    });
    let rig = loaded.map_err(error)?;
    Ok(Rig { rig, file: path.display().to_string() })
}

/// Held while a file loads under its own memory budget ([`load`]).
static LOADING: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// A loaded file: its skeleton, clips and meshes, and what can be asked of it.
#[pyclass(frozen, module = "bonescope")]
struct Rig {
    rig: bonescope_core::model::Rig,
    /// The path it was loaded from, as given.
    file: String,
}

/// One bone (a node of the file): its name, parent index, declared inheritance mode and role.
#[pyclass(frozen, get_all, module = "bonescope")]
struct Bone {
    index: usize,
    name: String,
    parent: Option<usize>,
    /// The mode the file declares (`full` where the format has none).
    mode: String,
    /// `joint`, `end site`, `mesh`, `camera`, `light` or `helper`.
    role: String,
}

/// One animation of the file.
#[pyclass(frozen, get_all, module = "bonescope")]
struct Clip {
    index: usize,
    name: Option<String>,
    /// Where it starts on its file's clock, seconds (a glb's first key, a USD stage's start time code over its rate,
    /// an FBX take's stored start).
    start: f64,
    /// How long it plays, seconds.
    duration: f64,
    /// Frames per second: the file's, or the one its key times show.
    frame_rate: f64,
    /// Every key time, in seconds, sorted.
    key_times: Vec<f64>,
}

/// One mesh of the file.
#[pyclass(frozen, get_all, module = "bonescope")]
struct Mesh {
    name: String,
    vertices: usize,
    /// The bone it hangs from.
    bone: usize,
    skinned: bool,
    morph_targets: usize,
}

/// `name` as Python writes a string in a repr, or `None`.
fn quoted(name: Option<&str>) -> String {
    name.map_or_else(|| "None".to_owned(), |name| format!("{name:?}"))
}

#[pymethods]
impl Bone {
    fn __repr__(&self) -> String {
        let parent = self.parent.map_or_else(|| "None".to_owned(), |p| p.to_string());
        format!(
            "<bonescope.Bone {} {}: {}, parent {parent}, mode {}>",
            self.index,
            quoted(Some(&self.name)),
            self.role,
            self.mode
        )
    }
}

#[pymethods]
impl Clip {
    fn __repr__(&self) -> String {
        let (name, keys) = (quoted(self.name.as_deref()), self.key_times.len());
        format!(
            "<bonescope.Clip {} {name}: {:.3} s from {:.4} s, {} fps, {keys} key times>",
            self.index, self.duration, self.start, self.frame_rate
        )
    }
}

#[pymethods]
impl Mesh {
    fn __repr__(&self) -> String {
        let skinned = if self.skinned { "skinned" } else { "not skinned" };
        format!(
            "<bonescope.Mesh {}: {} vertices on bone {}, {skinned}, {} morph targets>",
            quoted(Some(&self.name)),
            self.vertices,
            self.bone,
            self.morph_targets
        )
    }
}

#[pymethods]
impl Rig {
    /// The path the rig was loaded from.
    #[getter]
    fn file(&self) -> &str {
        &self.file
    }

    /// Every bone, parents before children.
    #[getter]
    fn bones(&self) -> Vec<Bone> {
        let bones = self.rig.skeleton.bones().iter().enumerate();
        bones
            .map(|(index, b)| Bone {
                index,
                name: b.name.clone(),
                parent: b.parent,
                mode: b.inherit.id().to_owned(),
                role: b.role.label().to_owned(),
            })
            .collect()
    }

    /// Every animation.
    #[getter]
    fn clips(&self) -> Vec<Clip> {
        let clips = self.rig.clips.iter();
        clips
            .map(|c| Clip {
                index: c.index,
                name: c.name.clone(),
                start: c.span().start,
                duration: c.span().length(),
                frame_rate: c.frame_rate(),
                key_times: c.key_times(),
            })
            .collect()
    }

    /// Every mesh.
    #[getter]
    fn meshes(&self) -> Vec<Mesh> {
        let meshes = self.rig.meshes.iter();
        meshes
            .map(|m| Mesh {
                name: m.name.clone(),
                vertices: m.positions.len(),
                bone: m.bone,
                skinned: m.skin.is_some(),
                morph_targets: m.morph_targets.len(),
            })
            .collect()
    }

    /// What the importer says about the file: units and axes and what became of them, how animation was read,
    /// what was skipped.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.rig.notes.clone()
    }

    /// The unit the file's lengths are in, as the reports write it (`"metres"` for glTF, FBX and USD), or `None` (BVH).
    #[getter]
    fn unit(&self) -> Option<String> {
        self.rig.unit.map(|u| u.to_string())
    }

    fn __repr__(&self) -> String {
        let (bones, clips) = (self.rig.skeleton.len(), self.rig.clips.len());
        format!("<bonescope.Rig {:?}: {bones} bones, {clips} clips, {} meshes>", self.file, self.rig.meshes.len())
    }

    /// Every bone at `times` (seconds; default: every key time plus `rate` per second, as `scan` samples) as
    /// numpy arrays, times first then bones: see `Evaluation`. `clip` is a name or index (default: the clip the
    /// command line opens); `modes` one mode for every bone (`"declared"`, `"full"`, `"segment-compensate"`, …) or
    /// a dict of bone names to modes (the others as declared); `layers` the runtime techniques as
    /// `bonescope inspect --format json` echoes them (`{"uniform_scale": [3], "bind_weight": 0.5, …}`).
    #[pyo3(signature = (clip = None, times = None, *, modes = None, layers = None, rate = 60.0,
        min_anisotropy = None, min_stretch_deg = None, min_shear_deg = None, min_non_uniform = None))]
    #[allow(clippy::too_many_arguments)]
    fn evaluate(
        &self,
        py: Python<'_>,
        clip: Option<&Bound<'_, PyAny>>,
        times: Option<Vec<f64>>,
        modes: Option<&Bound<'_, PyAny>>,
        layers: Option<&Bound<'_, PyAny>>,
        rate: f64,
        min_anisotropy: Option<f64>,
        min_stretch_deg: Option<f64>,
        min_shear_deg: Option<f64>,
        min_non_uniform: Option<f64>,
    ) -> PyResult<EvaluationArrays> {
        let setup = self.setup(py, clip, modes, layers)?;
        let ScanOptions { rate, tolerances } =
            scan_options(rate, [min_anisotropy, min_stretch_deg, min_shear_deg, min_non_uniform])?;
        if let Some(bad) = times.iter().flatten().find(|t| !t.is_finite()) {
            return Err(error(format!("times must be finite numbers of seconds, got {bad}")));
        }
        let rig = &self.rig;
        let sampled = py.detach(|| {
            let evaluation = Evaluation::of(rig, &setup).map_err(|e| e.to_string())?;
            let times = times.unwrap_or_else(|| evaluation.times(rate));
            Ok::<_, String>(sample(&evaluation, &times, &tolerances))
        });
        let sampled = sampled.map_err(error)?;
        EvaluationArrays::new(py, sampled, rig.skeleton.bones().iter().map(|b| b.name.clone()).collect())
    }

    /// Whole clips scanned as `bonescope scan FILE --format json` reports this file: `{"file", "error",
    /// "animations": [...]}`, each animation with its stretched bones (worst shear, when, how often) and, with
    /// `explain=True`, each one's main cause and best fix. `clip` as for `evaluate` (default: every clip).
    #[pyo3(signature = (clip = None, *, modes = None, layers = None, rate = 60.0, explain = false,
        min_anisotropy = None, min_stretch_deg = None, min_shear_deg = None, min_non_uniform = None))]
    #[allow(clippy::too_many_arguments)]
    fn scan(
        &self,
        py: Python<'_>,
        clip: Option<&Bound<'_, PyAny>>,
        modes: Option<&Bound<'_, PyAny>>,
        layers: Option<&Bound<'_, PyAny>>,
        rate: f64,
        explain: bool,
        min_anisotropy: Option<f64>,
        min_stretch_deg: Option<f64>,
        min_shear_deg: Option<f64>,
        min_non_uniform: Option<f64>,
    ) -> PyResult<Py<PyAny>> {
        let setup = self.setup(py, clip, modes, layers)?;
        let options = scan_options(rate, [min_anisotropy, min_stretch_deg, min_shear_deg, min_non_uniform])?;
        let clips: Vec<Option<usize>> = match (clip, self.rig.clips.len()) {
            (Some(_), _) => vec![setup.clip],
            (None, 0) => vec![None],
            (None, count) => (0..count).map(Some).collect(),
        };
        let evaluations: Vec<Evaluation> = clips
            .into_iter()
            .map(|clip| Evaluation::of(&self.rig, &Setup { clip, ..setup.clone() }).map_err(error))
            .collect::<PyResult<_>>()?;
        let animations = interruptible(py, |cancel| {
            evaluations.iter().map(|evaluation| scan_clip(evaluation, &options, explain, cancel)).collect()
        })?;
        json_value(py, &FileReport::new(self.file.clone(), Ok::<_, String>(animations)))
    }

    /// Why bones shear, as `bonescope explain FILE --format json` says it: for each of `bone` (a name, an index, or
    /// a list of them; default every stretched bone, the worst first) its chain, the main causes over the clip, and
    /// every fix ranked by how far it moves the skin. `time` details the chain there (default: where each bone
    /// shears most).
    #[pyo3(signature = (bone = None, *, time = None, clip = None, modes = None, layers = None, rate = 60.0,
        min_anisotropy = None, min_stretch_deg = None, min_shear_deg = None, min_non_uniform = None))]
    #[allow(clippy::too_many_arguments)]
    fn explain(
        &self,
        py: Python<'_>,
        bone: Option<&Bound<'_, PyAny>>,
        time: Option<f64>,
        clip: Option<&Bound<'_, PyAny>>,
        modes: Option<&Bound<'_, PyAny>>,
        layers: Option<&Bound<'_, PyAny>>,
        rate: f64,
        min_anisotropy: Option<f64>,
        min_stretch_deg: Option<f64>,
        min_shear_deg: Option<f64>,
        min_non_uniform: Option<f64>,
    ) -> PyResult<Py<PyAny>> {
        let setup = self.setup(py, clip, modes, layers)?;
        let options = scan_options(rate, [min_anisotropy, min_stretch_deg, min_shear_deg, min_non_uniform])?;
        if let Some(time) = time.filter(|t| !t.is_finite()) {
            return Err(error(format!("time must be a finite number of seconds, got {time}")));
        }
        let bones = match bone {
            None => None,
            Some(one) if one.is_instance_of::<PyString>() || one.extract::<usize>().is_ok() => {
                Some(vec![self.bone(one)?])
            }
            Some(many) => Some(many.try_iter()?.map(|b| self.bone(&b?)).collect::<PyResult<Vec<_>>>()?),
        };
        let evaluation = Evaluation::of(&self.rig, &setup).map_err(error)?;
        let explained = py.detach(|| {
            let before = bonescope_core::analysis::scan_analysis(&evaluation, &options);
            let question = Question { bones: bones.as_deref(), at: time, costs: Costs::Every, scale: None };
            explain(&evaluation, &before, question, &options)
        });
        json_value(py, &Report::new(self.file.clone(), &evaluation, options.rate, &explained))
    }
}

impl Rig {
    /// What is evaluated: the clip (a name or index; default the one the command line opens), the modes, the layers.
    fn setup(
        &self,
        py: Python<'_>,
        clip: Option<&Bound<'_, PyAny>>,
        modes: Option<&Bound<'_, PyAny>>,
        layers: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Setup> {
        let rig = &self.rig;
        let clip = match clip {
            None => Setup::declared(rig).clip,
            Some(name) => {
                let name = name.str()?.to_string();
                let clip = rig.clip_named(&name).map_err(error)?;
                rig.clips.iter().position(|c| std::ptr::eq(c, clip))
            }
        };
        let layers = match layers {
            None => Layers::default(),
            Some(layers) => {
                let text: String = py.import("json")?.call_method1("dumps", (layers,))?.extract()?;
                serde_json::from_str(&text).map_err(|e| error(format!("layers: {e}")))?
            }
        };
        Ok(Setup { clip, modes: self.modes(modes)?, layers, ..Setup::default() })
    }

    /// `modes` as a mode id for every bone, or a dict of bone names (or indices) to mode ids.
    fn modes(&self, modes: Option<&Bound<'_, PyAny>>) -> PyResult<Modes> {
        let Some(modes) = modes else { return Ok(Modes::default()) };
        if let Ok(dict) = modes.cast::<PyDict>() {
            let mut each = Modes::default();
            for (bone, mode) in dict.iter() {
                let bone = self.bone(&bone)?;
                each.set(&self.rig.skeleton, bone, mode_choice(&mode.extract::<String>()?)?);
            }
            return Ok(each);
        }
        Ok(Modes::all(mode_choice(&modes.extract::<String>()?)?))
    }

    /// The bone named `bone`, or with index `bone`.
    fn bone(&self, bone: &Bound<'_, PyAny>) -> PyResult<usize> {
        let skeleton = &self.rig.skeleton;
        if let Ok(index) = bone.extract::<usize>() {
            return (index < skeleton.len())
                .then_some(index)
                .ok_or_else(|| error(format!("no bone {index} (the rig has {})", skeleton.len())));
        }
        let name: String = bone.extract()?;
        skeleton.find(&name).ok_or_else(|| error(format!("no bone named `{name}`")))
    }
}

/// A mode id: `declared` or a mode's.
fn mode_choice(id: &str) -> PyResult<ModeChoice> {
    id.parse::<ModeChoice>().map_err(error)
}

/// How clips are sampled and judged: `rate` samples per second (finite, > 0) on top of the key times, and the
/// verdicts' tolerances `[min_anisotropy, min_stretch_deg, min_shear_deg, min_non_uniform]`, each a finite number
/// ≥ 0 (the defaults for `None`).
fn scan_options(rate: f64, [anisotropy, stretch, shear, non_uniform]: [Option<f64>; 4]) -> PyResult<ScanOptions> {
    let defaults = Tolerances::default();
    let value = |name: &str, given: Option<f64>, default: f64| match given {
        None => Ok(default),
        Some(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Some(v) => Err(error(format!("{name} must be a finite number ≥ 0, got {v}"))),
    };
    let tolerances = Tolerances {
        min_anisotropy: value("min_anisotropy", anisotropy, defaults.min_anisotropy)?,
        min_stretch_deg: value("min_stretch_deg", stretch, defaults.min_stretch_deg)?,
        min_shear_deg: value("min_shear_deg", shear, defaults.min_shear_deg)?,
        min_non_uniform: value("min_non_uniform", non_uniform, defaults.min_non_uniform)?,
        ..defaults
    };
    Ok(ScanOptions { rate: positive_rate(rate)?, tolerances })
}

/// Samples per second: a finite number > 0.
fn positive_rate(rate: f64) -> PyResult<f64> {
    (rate.is_finite() && rate > 0.0)
        .then_some(rate)
        .ok_or_else(|| error(format!("rate must be a finite number > 0, got {rate}")))
}

/// Every bone of a clip at every time asked for, as numpy arrays indexed `[time, bone, ...]` (float64 unless
/// said): matrices `m[t, b, row, column]` with column vectors (the translation in `m[t, b, :3, 3]`), quaternions
/// `[x, y, z, w]`. The model matrix's parts are Shoemake's `M = T·F·R·U·K·Uᵀ`, as `bonescope inspect` prints them
/// (scale factors as the file's author set them: a unit conversion above the bone divided out).
#[pyclass(frozen, get_all, name = "Evaluation", module = "bonescope")]
struct EvaluationArrays {
    /// `(T,)`: the times, in seconds.
    times: Py<PyAny>,
    /// The bones' names, in index order.
    bones: Vec<String>,
    /// `(T, B, 4, 4)`: each bone's local matrix (relative to its parent, as its mode makes it).
    local: Py<PyAny>,
    /// `(T, B, 4, 4)`: each bone's model matrix (the whole chain, in metres, Y up).
    model: Py<PyAny>,
    /// `(T, B, 3)`: `T`.
    translation: Py<PyAny>,
    /// `(T, B, 4)`: the essential rotation `R`.
    rotation: Py<PyAny>,
    /// `(T, B, 4)`: the stretch rotation `U`, the frame the scale factors apply in.
    stretch: Py<PyAny>,
    /// `(T, B, 3)`: the scale factors `K`.
    scale: Py<PyAny>,
    /// `(T, B)`: `F`, 1 or −1 (mirrored).
    sign: Py<PyAny>,
    /// `(T, B)`: the largest deviation from 90° between two columns of the model matrix, in degrees, at each time:
    /// its maximum over the times is the sampled worst, which `Rig.scan` refines between the samples
    /// (`worst_shear_deg`, as the command line reports it).
    shear_deg: Py<PyAny>,
    /// `(T, B)`: the angle of `U`, in degrees (scale factors within the anisotropy tolerance of each other merged).
    stretch_deg: Py<PyAny>,
    /// `(T, B)`, bool: stretched (scale along axes that shear) under the tolerances.
    stretched: Py<PyAny>,
}

impl EvaluationArrays {
    /// `sampled`'s buffers handed to numpy as they are (no copy): each becomes the memory of its array.
    fn new(py: Python<'_>, sampled: bonescope_core::analysis::Sampled, bones: Vec<String>) -> PyResult<Self> {
        let (t, b) = (sampled.times.len(), sampled.bones);
        fn array<T: numpy::Element>(py: Python<'_>, data: Vec<T>, shape: &[usize]) -> PyResult<Py<PyAny>> {
            let array = Array::from_shape_vec(IxDyn(shape), data).map_err(error)?;
            Ok(PyArray::from_owned_array(py, array).into_any().unbind())
        }
        Ok(EvaluationArrays {
            times: array(py, sampled.times, &[t])?,
            bones,
            local: array(py, sampled.local, &[t, b, 4, 4])?,
            model: array(py, sampled.model, &[t, b, 4, 4])?,
            translation: array(py, sampled.translation, &[t, b, 3])?,
            rotation: array(py, sampled.rotation, &[t, b, 4])?,
            stretch: array(py, sampled.stretch, &[t, b, 4])?,
            scale: array(py, sampled.scale, &[t, b, 3])?,
            sign: array(py, sampled.sign, &[t, b])?,
            shear_deg: array(py, sampled.shear_deg, &[t, b])?,
            stretch_deg: array(py, sampled.stretch_deg, &[t, b])?,
            stretched: array(py, sampled.stretched, &[t, b])?,
        })
    }
}

#[pymethods]
impl EvaluationArrays {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let times = self.times.bind(py).len()?;
        Ok(format!("<bonescope.Evaluation: {times} times × {} bones>", self.bones.len()))
    }
}

/// Two files compared over time, bone by bone and vertex by vertex, as `bonescope diff A B --format json` says it.
/// `a` and `b` are paths; the keyword arguments are `diff`'s options (`anim_a="walk"`, `inherit_b="full"`,
/// `map={"Hips": "pelvis"}`, `interp="nlerp"`, `unit_b="cm"`, `up_b="z"`, `align="start"`, …).
#[pyfunction]
#[pyo3(signature = (a, b, *, anim_a = None, anim_b = None, inherit_a = "declared", inherit_b = "declared",
    map = None, interp = None, rate = 60.0, unit_a = None, unit_b = None, up_a = None, up_b = None,
    align = None))]
#[allow(clippy::too_many_arguments)]
fn diff(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    anim_a: Option<&Bound<'_, PyAny>>,
    anim_b: Option<&Bound<'_, PyAny>>,
    inherit_a: &str,
    inherit_b: &str,
    map: Option<std::collections::BTreeMap<String, String>>,
    interp: Option<&str>,
    rate: f64,
    unit_a: Option<&str>,
    unit_b: Option<&str>,
    up_a: Option<&str>,
    up_b: Option<&str>,
    align: Option<&Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    let paths = [path_of(a)?, path_of(b)?];
    let align = match align {
        Some(align) => align.str()?.to_string().parse().map_err(|why: String| error(format!("align: {why}")))?,
        None => Align::Clocks,
    };
    let names = [
        anim_a.map(|n| n.str().map(|s| s.to_string())).transpose()?,
        anim_b.map(|n| n.str().map(|s| s.to_string())).transpose()?,
    ];
    let modes = [mode_choice(inherit_a)?, mode_choice(inherit_b)?];
    let units = [unit_a.map(parse_unit).transpose()?, unit_b.map(parse_unit).transpose()?];
    let ups = [up_a.map(parse_choice::<UpAxis>).transpose()?, up_b.map(parse_choice::<UpAxis>).transpose()?];
    let interp = interp.map(parse_choice::<RotationInterpolation>).transpose()?;
    let rate = positive_rate(rate)?;
    let map: Vec<(String, String)> = map.unwrap_or_default().into_iter().collect();
    let compared = py.detach(|| -> Result<_, String> {
        let rig = |side: usize| -> Result<bonescope_core::model::Rig, String> {
            let rig = import::load(&paths[side]).map_err(|e| e.to_string())?;
            let rig = match ups[side] {
                Some(up) => rig.stood_up(up),
                None => rig,
            };
            rig.given_unit(units[side]).map_err(|why| format!("unit_{}: {why}", ["a", "b"][side]))
        };
        let rigs = [rig(0)?, rig(1)?];
        let names = [names[0].as_deref(), names[1].as_deref()];
        let chosen = chosen_clips([&rigs[0], &rigs[1]], names).map_err(|missing| {
            let file = paths[missing.searched].display();
            format!("{file}: anim_{}: {}", ["a", "b"][missing.named_by], missing.why)
        })?;
        let side = |s: usize| FileSide::new(paths[s].display().to_string(), &rigs[s], modes[s], chosen.map(|c| c[s]));
        let (side_a, mut side_b) = (side(0), side(1));
        if let Some(interp) = interp {
            side_b.setup.layers.interpolation.rotation = interp;
        }
        let clips = if chosen.is_some() { Clips::Chosen } else { Clips::ByName };
        diff_files(&side_a, &side_b, clips, &map, rate, align).map_err(|e| e.to_string())
    });
    json_value(py, &compared.map_err(error)?)
}

/// A unit: `m`, `cm`, `mm`, `in`, `ft`, `cmu`, or a length in metres.
fn parse_unit(text: &str) -> PyResult<Unit> {
    text.parse::<Unit>().map_err(error)
}

/// A value of a choice by its id, with the ids there are in the error.
fn parse_choice<T: Choice>(id: &str) -> PyResult<T> {
    T::from_id(id).ok_or_else(|| {
        let ids: Vec<&str> = T::ALL.iter().map(|v| v.id()).collect();
        error(format!("invalid value `{id}` (possible values: {})", ids.join(", ")))
    })
}

/// Bakes `path` (any file bonescope reads) into a file at `out` that `engine`'s runtime plays as the source evaluates
/// (a glTF binary `.glb`, or a UsdSkel stage `.usda`, `.usdc` or `.usdz` of one clip), in metres, and returns the report `bonescope bake --format json` prints (measured on the file
/// read back): the same bake as the command line's. `engine`: `generic`, `blender`, `three`, `godot`, `unity` or
/// `unreal`; `strategy` (`exact` or `trs`) overrides the engine's; `tolerance` is the fraction of the rig's size the
/// keys may stray; `clip`, `modes` and `layers` as for `Rig.evaluate` (default every clip under the declared modes);
/// `unit` is the source's where its file states none (BVH), else the one its figure stands a person's height in.
#[pyfunction]
#[pyo3(signature = (path, out, engine = "generic", *, strategy = None, tolerance = 1e-4, clip = None, modes = None,
    layers = None, unit = None))]
#[allow(clippy::too_many_arguments)]
fn bake(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    out: &Bound<'_, PyAny>,
    engine: &str,
    strategy: Option<&str>,
    tolerance: f64,
    clip: Option<&Bound<'_, PyAny>>,
    modes: Option<&Bound<'_, PyAny>>,
    layers: Option<&Bound<'_, PyAny>>,
    unit: Option<&str>,
) -> PyResult<Py<PyAny>> {
    let out = path_of(out)?;
    let engine = parse_choice::<Engine>(engine)?;
    let plan = Plan { engine, strategy: strategy.map(parse_choice::<Strategy>).transpose()?, tolerance };
    let unit = unit.map(parse_unit).transpose()?;
    let Rig { rig, file } = load(py, path, None)?;
    let (rig, assumed) = in_metres(rig, unit).map_err(|why| error(format!("unit: {why}")))?;
    let source = Rig { rig, file };
    // glTF is in metres: a source in another unit is measured in them.
    let setup = Setup { unit: Some(Unit::METRE), ..source.setup(py, clip, modes, layers)? };
    let chosen = clip.is_some();
    let written = py.detach(|| -> Result<_, String> {
        let evaluation = Evaluation::of(&source.rig, &setup).map_err(|e| e.to_string())?;
        let only = chosen.then_some(evaluation.clip).flatten();
        bake_file(&evaluation, &source.file, only, &plan, &out).map_err(|e| e.to_string())
    });
    let mut report = written.map_err(error)?.report;
    report.notes.extend(assumed.map(|note| format!("{note} (unit= to choose)")));
    json_value(py, &report)
}

/// See what a skeletal animation really does to every bone: the polar decomposition of every bone's matrix over
/// time, shear and scale inheritance, why a bone shears and the cheapest fix, and bakes every engine plays.
#[pymodule]
#[pyo3(name = "bonescope")]
fn init(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    module.add("Error", module.py().get_type::<Error>())?;
    module.add_function(wrap_pyfunction!(load, module)?)?;
    module.add_function(wrap_pyfunction!(diff, module)?)?;
    module.add_function(wrap_pyfunction!(bake, module)?)?;
    module.add_class::<Rig>()?;
    module.add_class::<Bone>()?;
    module.add_class::<Clip>()?;
    module.add_class::<Mesh>()?;
    module.add_class::<EvaluationArrays>()?;
    Ok(())
}
