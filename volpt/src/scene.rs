//! [`Scene`]: a scene loaded from any supported source, with its settings resolved, and the
//! parameters that change between renders without reloading its grids.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use volpt_core::grid::HALF_MAX;
use volpt_core::PathSettings;
use volpt_film::{Film, RenderOptions};
use volpt_render::factory::{FactoryCache, Parts};
use volpt_render::{Effects, Variant};
use volpt_scene::medium::{MediumParam, ParamRefused};
use volpt_scene::toml_scene::look_at;
use volpt_scene::validate::CheckedData;
use volpt_scene::{
    AlbedoDesc, DensityDesc, GridDesc, GridLookup, GridStorage, LightsDesc, MediumDesc,
    NumberParam, PhaseDesc, SampleLayout, SceneAssembler, SceneBuilder, SceneDescription,
};

use crate::settings::RenderSettings;
use crate::{Error, Named};

/// A scene ready to render: its description, the path settings and variant choice it renders with,
/// and its seed.
#[derive(Debug)]
pub struct Scene {
    /// Names the scene in errors: its file, or the builder's source.
    source: String,
    desc: SceneDescription,
    path: PathSettings,
    effects: Effects,
    seed: u32,
    threads: Option<usize>,
    /// The up direction a camera move keeps (`camera.up`): the camera's own up as loaded, until
    /// set. A look-at frame forgets the up it was built from, and re-deriving it from the frame
    /// would roll the camera at every move.
    up: [f32; 3],
    /// Whether the grid lookup was chosen (a setting, [`Scene::set_lookup`]) rather than left to
    /// the backend's default ([`crate::Backend::default_lookup`]).
    lookup_chosen: bool,
    /// What is known of the grids' values: replaced with them ([`Scene::set_grid`]), never
    /// changed in place, so that what names the values names one set of values.
    data: Arc<DataFacts>,
    /// The description as a backend that stores or looks up the grids otherwise reads it, made by
    /// the first render that needed it ([`Scene::read_as`]); dropped by every change of the
    /// description.
    read_otherwise: Mutex<Option<Arc<SceneDescription>>>,
}

/// How a backend reads a scene's grids: its storage, and the lookup a render uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Reading {
    pub storage: GridStorage,
    pub lookup: GridLookup,
}

/// A scene's description as one render reads it: the scene's own, or a copy read otherwise.
pub(crate) enum ReadAs<'a> {
    Own(&'a SceneDescription),
    Copy(Arc<SceneDescription>),
}

impl std::ops::Deref for ReadAs<'_> {
    type Target = SceneDescription;

    fn deref(&self) -> &SceneDescription {
        match self {
            ReadAs::Own(desc) => desc,
            ReadAs::Copy(desc) => desc,
        }
    }
}

/// What a scene's data (its grids and environment map) was found to be, computed once: a scene
/// rendered again and again with another camera or parameters (a viewer's frames, the batches of
/// several GPUs) neither reads nor copies its grids again.
#[derive(Debug)]
struct DataFacts {
    /// Names this scene's grids for a GPU that keeps them between renders: unique to the scene
    /// (a clone gets its own, its grids being another copy).
    id: u64,
    /// What checking every value found ([`volpt_scene::validate`]).
    checked: CheckedData,
    /// The factory's scans of the grids and the last majorant grid.
    factory: FactoryCache,
    /// The grids' and the map's values hashed ([`crate::fingerprint`]), on first use.
    content: OnceLock<u64>,
}

impl DataFacts {
    fn new(checked: CheckedData) -> Self {
        static NEXT_ID: AtomicU64 = AtomicU64::new(1);
        Self {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            checked,
            factory: FactoryCache::new(),
            content: OnceLock::new(),
        }
    }
}

impl Clone for Scene {
    fn clone(&self) -> Self {
        let data = DataFacts::new(self.data.checked);
        if let Some(&content) = self.data.content.get() {
            let _ = data.content.set(content);
        }
        Self {
            source: self.source.clone(),
            desc: self.desc.clone(),
            path: self.path,
            effects: self.effects,
            seed: self.seed,
            threads: self.threads,
            up: self.up,
            lookup_chosen: self.lookup_chosen,
            data: Arc::new(data),
            read_otherwise: Mutex::new(None),
        }
    }
}

/// A parameter's value ([`Scene::get`], [`Scene::set`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    Int(i64),
    Float(f32),
    Rgb([f32; 3]),
    Vec3([f32; 3]),
}

/// The parameters a scene takes between renders: key and what it is. The scene's own, then the
/// medium's ([`MediumDesc::PARAMS`]), the lights' ([`LightsDesc::PARAMS`]: a scene has those of
/// the lights it has), then the phase's ([`PhaseDesc::PARAMS`]).
pub const PARAMS: &[(&str, &str)] = &with_numbers::<
    {
        SCENE_PARAMS.len()
            + MediumDesc::PARAMS.len()
            + LightsDesc::PARAMS.len()
            + PhaseDesc::PARAMS.len()
    },
>(
    &[SCENE_PARAMS, MediumDesc::PARAMS, LightsDesc::PARAMS],
    PhaseDesc::PARAMS,
);

/// Each of `keys`, then the key and description of each of `numbers`, `N` in all.
const fn with_numbers<const N: usize>(
    keys: &[&[(&'static str, &'static str)]],
    numbers: &[NumberParam],
) -> [(&'static str, &'static str); N] {
    let mut all = [("", ""); N];
    let mut i = 0;
    let mut k = 0;
    while k < keys.len() {
        let mut n = 0;
        while n < keys[k].len() {
            all[i] = keys[k][n];
            i += 1;
            n += 1;
        }
        k += 1;
    }
    let mut j = 0;
    while j < numbers.len() {
        all[i + j] = (numbers[j].key, numbers[j].about);
        j += 1;
    }
    all
}

/// The parameters the scene holds apart from its parts' descriptions.
const SCENE_PARAMS: &[(&str, &str)] = &[
    ("spp", "samples per pixel, an integer of at least 1"),
    (
        "seed",
        "seed of the random streams, an integer from 0 to 2^32 - 1",
    ),
    (
        "max_depth",
        "longest path in segments, an integer; -1 is unlimited",
    ),
    (
        "rr_depth",
        "depth from which Russian roulette runs, an integer; -1 never (but for paths of negligible \
         weight)",
    ),
    ("camera.origin", "the camera's position, a 3-vector"),
    (
        "camera.target",
        "a point the camera looks at (get: one unit ahead), a 3-vector",
    ),
    (
        "camera.up",
        "the up direction camera moves keep, a 3-vector (as loaded: the camera's own up; set \
         the world's up, e.g. [0, 1, 0], to orbit without roll)",
    ),
    (
        "camera.fov",
        "the field of view in degrees along the scene's fov axis, in (0, 180)",
    ),
];

impl Scene {
    /// Loads the scene file at `path` (Mitsuba XML, volpt TOML, or a grid file) with `settings`
    /// over its own values.
    pub fn load(path: impl AsRef<Path>, settings: &RenderSettings) -> Result<Self, Error> {
        let builder = volpt_scene::builder_for(path.as_ref())?;
        Self::build(builder.as_ref(), settings)
    }

    /// The scene `builder` makes (any source, e.g. one written in code), with `settings` over it.
    pub fn build(builder: &dyn SceneBuilder, settings: &RenderSettings) -> Result<Self, Error> {
        settings.check_threads()?;
        let (mut desc, checked) =
            SceneAssembler::new(settings.config()).assemble_checked(builder)?;
        if let Some(lookup) = settings.lookup {
            desc.medium.lookup = lookup;
        }
        check_lookup(&desc, desc.medium.lookup, checked)?;
        let m = &desc.camera.to_world;
        let scene = Self {
            up: [m[0][1], m[1][1], m[2][1]],
            source: builder.source(),
            path: settings.path_settings(&desc)?,
            effects: settings.effects,
            seed: settings.seed,
            threads: settings.threads,
            lookup_chosen: settings.lookup.is_some(),
            desc,
            data: Arc::new(DataFacts::new(checked)),
            read_otherwise: Mutex::new(None),
        };
        let boundary = scene.variant().boundary;
        if scene.desc.lights.any_delta() && !boundary.index_matched() {
            tracing::warn!(
                "{}: {}",
                scene.source,
                crate::info::delta_behind_dielectric(boundary.rough())
            );
        }
        Ok(scene)
    }

    pub fn description(&self) -> &SceneDescription {
        &self.desc
    }

    /// The scene file, or the builder's source.
    pub fn source(&self) -> &str {
        &self.source
    }

    pub fn path_settings(&self) -> PathSettings {
        self.path
    }

    pub fn effects(&self) -> Effects {
        self.effects
    }

    /// The monomorphised variant the factory picks for this scene.
    pub fn variant(&self) -> Variant {
        Parts::of_cached(&self.desc, self.effects, &self.data.factory).variant()
    }

    pub fn spp(&self) -> u32 {
        self.desc.spp
    }

    pub fn seed(&self) -> u32 {
        self.seed
    }

    pub fn resolution(&self) -> (u32, u32) {
        (self.desc.film.width, self.desc.film.height)
    }

    /// An empty film of this scene's size.
    pub fn film(&self) -> Film {
        let (width, height) = self.resolution();
        Film::new(width, height)
    }

    /// Samples per pixel, seed and threads, as the backends take them.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            spp: self.desc.spp,
            seed: self.seed,
            threads: self.threads,
        }
    }

    /// What the scene loads to, field by field: `volpt info`'s text ([`crate::info`]).
    pub fn info(&self) -> crate::Info {
        crate::info::describe(&self.source, &self.desc, self.effects, &self.path)
    }

    /// What makes two renders the same render ([`crate::fingerprint`]): of this scene rendered
    /// as loaded, on the CPU. A render's own is [`crate::Backend::fingerprint`].
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint_of(&self.desc, &self.path, self.effects)
    }

    /// The fingerprint of rendering `desc` (this scene's, or it read otherwise) with `path` and
    /// `effects`.
    pub(crate) fn fingerprint_of(
        &self,
        desc: &SceneDescription,
        path: &PathSettings,
        effects: Effects,
    ) -> u64 {
        // The grids' values are the same however they are read.
        let content = *self
            .data
            .content
            .get_or_init(|| crate::fingerprint::content(&self.desc));
        crate::fingerprint::fingerprint(desc, path, effects, content)
    }

    /// Replaces the path settings (tracking, estimator, roulette, depths) the scene renders with
    /// by default ([`crate::RenderRequest::path`] chooses them for one render).
    pub fn set_path_settings(&mut self, settings: PathSettings) {
        self.path = settings;
    }

    /// The seed of the random streams: renders of different seeds are independent. One render's
    /// own is [`crate::RenderRequest::seed`].
    pub fn set_seed(&mut self, seed: u32) {
        self.seed = seed;
    }

    pub fn set_effects(&mut self, effects: Effects) {
        self.effects = effects;
    }

    /// How the grids are reconstructed; refused where the grids' values do not fit the lookup.
    /// A lookup set here is every backend's (no backend default replaces it).
    pub fn set_lookup(&mut self, lookup: GridLookup) -> Result<(), Error> {
        check_lookup(&self.desc, lookup, self.data.checked)?;
        self.desc.medium.lookup = lookup;
        self.lookup_chosen = true;
        self.changed();
        Ok(())
    }

    /// Forgets the description read otherwise, made of the one just changed.
    fn changed(&mut self) {
        *self
            .read_otherwise
            .get_mut()
            .unwrap_or_else(|p| p.into_inner()) = None;
    }

    /// The description read as `reading` says: the scene's own where it reads so, else a copy
    /// (kept for the next render that reads it so). `reading`'s lookup is checked against the
    /// grids as [`Scene::set_lookup`] checks it.
    pub(crate) fn read_as(&self, reading: Reading) -> Result<ReadAs<'_>, Error> {
        let reads = |d: &SceneDescription| {
            d.medium.storage == reading.storage && d.medium.lookup == reading.lookup
        };
        if reads(&self.desc) {
            return Ok(ReadAs::Own(&self.desc));
        }
        check_lookup(&self.desc, reading.lookup, self.data.checked)?;
        let mut kept = self
            .read_otherwise
            .lock()
            .unwrap_or_else(|p| p.into_inner());
        if let Some(desc) = kept.as_ref().filter(|d| reads(d)) {
            return Ok(ReadAs::Copy(desc.clone()));
        }
        let mut desc = self.desc.clone();
        desc.medium.storage = reading.storage;
        desc.medium.lookup = reading.lookup;
        let desc = Arc::new(desc);
        *kept = Some(desc.clone());
        Ok(ReadAs::Copy(desc))
    }

    /// Reads the grids as `reading` says from now on, in place: renders that read them so need
    /// no copy of the description ([`crate::Backend::adopt`]).
    pub(crate) fn adopt(&mut self, reading: Reading) {
        self.desc.medium.storage = reading.storage;
        if !self.lookup_chosen {
            self.desc.medium.lookup = reading.lookup;
        }
        self.changed();
    }

    /// Whether the lookup was chosen, by a setting or [`Scene::set_lookup`].
    pub fn lookup_chosen(&self) -> bool {
        self.lookup_chosen
    }

    /// The device bytes of the medium's grids as f32 textures (an RGB albedo takes four
    /// channels; constants none).
    pub(crate) fn texture_bytes(&self) -> u64 {
        let bytes = |g: &volpt_scene::GridDesc| {
            let channels = if g.channels == 1 { 1 } else { 4 };
            g.resolution.iter().map(|&r| u64::from(r)).product::<u64>() * channels * 4
        };
        self.desc.medium.grids().map(|(_, g)| bytes(g)).sum()
    }

    /// Renders `width` x `height` pixels from now on, without reloading the grids (an
    /// interactive viewer's reduced resolution while the view moves). The field of view stays
    /// along the scene's fov axis, so a size of the same aspect ratio frames the same picture.
    /// Refused, leaving the scene as it was, where the film does not fit the memory limit.
    pub fn set_resolution(&mut self, width: u32, height: u32) -> Result<(), Error> {
        let before = self.desc.film;
        self.desc.film.width = width;
        self.desc.film.height = height;
        self.changed();
        self.validate()
            .map_err(Error::from)
            .inspect_err(|_| self.desc.film = before)
    }

    /// The parameters this scene has, with what each is: those of [`PARAMS`] it can get (not
    /// `medium.albedo` beside an albedo grid), then a material-indexed volume's materials'
    /// coefficients (`materials.<name>.sigma_s`, `.sigma_a`, `.g`; [`MediumDesc::material_params`]).
    pub fn params(&self) -> Vec<(String, &'static str)> {
        PARAMS
            .iter()
            .filter(|(key, _)| self.get(key).is_ok())
            .map(|&(key, about)| (key.to_owned(), about))
            .chain(self.desc.medium.material_params())
            .collect()
    }

    /// The value of parameter `key` ([`PARAMS`], or a material's, [`Scene::params`]).
    pub fn get(&self, key: &str) -> Result<ParamValue, Error> {
        let d = &self.desc;
        let depth = |d: Option<u32>| ParamValue::Int(d.map_or(-1, i64::from));
        Ok(match key {
            "spp" => ParamValue::Int(d.spp.into()),
            "seed" => ParamValue::Int(self.seed.into()),
            "max_depth" => depth(d.integrator.max_depth),
            "rr_depth" => depth(d.integrator.rr_depth),
            "camera.origin" => ParamValue::Vec3(self.look_at().0),
            "camera.target" => ParamValue::Vec3(self.look_at().1),
            "camera.up" => ParamValue::Vec3(self.look_at().2),
            "camera.fov" => ParamValue::Float(d.camera.fov_degrees),
            _ if LightsDesc::PARAMS.iter().any(|&(k, _)| k == key) => {
                let absent = |what: &str| Error::Param {
                    key: key.to_owned(),
                    expected: format!("a scene with {what}"),
                    found: format!("a scene without: {}", d.lights),
                };
                let sun = || d.lights.sun.ok_or_else(|| absent("a sun"));
                let spot = || d.lights.spot.ok_or_else(|| absent("a point or spot light"));
                match key {
                    "sun.direction" => ParamValue::Vec3(sun()?.direction),
                    "sun.irradiance" => ParamValue::Rgb(sun()?.irradiance),
                    "sun.angular_radius" => ParamValue::Float(sun()?.angular_radius),
                    "light.position" => ParamValue::Vec3(spot()?.position),
                    "light.intensity" => ParamValue::Rgb(spot()?.intensity),
                    _ => ParamValue::Vec3(spot()?.cone.ok_or_else(|| absent("a spot"))?.direction),
                }
            }
            _ => match (d.medium.param(key), d.medium.phase.param(key)) {
                (Some(Ok(MediumParam::Float(v))), _) => ParamValue::Float(v),
                (Some(Ok(MediumParam::Rgb(v))), _) => ParamValue::Rgb(v),
                (Some(Err(refused)), _) => return Err(refusal(key, refused, "")),
                (None, Some(value)) => ParamValue::Float(value),
                (None, None) => return Err(unknown(key)),
            },
        })
    }

    /// The camera as a look-at: its origin, the point one unit ahead, and the up moves keep.
    fn look_at(&self) -> ([f32; 3], [f32; 3], [f32; 3]) {
        let m = &self.desc.camera.to_world;
        let column = |j: usize| [m[0][j], m[1][j], m[2][j]];
        let (origin, forward) = (column(3), column(2));
        let target = [0, 1, 2].map(|i| origin[i] + forward[i]);
        (origin, target, self.up)
    }

    /// Sets parameter `key` ([`PARAMS`], or a material's, [`Scene::params`]) to `value`. The
    /// scene is checked as a loaded one is; a value it refuses leaves the scene as it was.
    pub fn set(&mut self, key: &str, value: ParamValue) -> Result<(), Error> {
        let before = self.clone_light();
        self.changed();
        let result = self.apply(key, value).and_then(|()| {
            // A value the scene's checks refuse is this parameter's bad value: the error names
            // the parameter, and what the check expected of the scene.
            let refused = |error: volpt_scene::SceneError| match error {
                volpt_scene::SceneError::InvalidValue {
                    field,
                    expected,
                    found,
                    ..
                } => Error::Param {
                    key: key.to_owned(),
                    expected: format!("{expected} (the scene's {field})"),
                    found,
                },
                error => Error::Scene(error),
            };
            volpt_scene::numerics::check_position_resolution_settings(
                &self.desc,
                Path::new(&self.source),
                self.data.checked,
            )
            .map_err(refused)?;
            self.validate().map_err(refused)?;
            check_lookup(&self.desc, self.desc.medium.lookup, self.data.checked)
        });
        if result.is_err() {
            self.restore_light(before);
        }
        result
    }

    fn apply(&mut self, key: &str, value: ParamValue) -> Result<(), Error> {
        let wrong = |expected: &str| Error::Param {
            key: key.to_owned(),
            expected: expected.to_owned(),
            found: format!("{value:?}"),
        };
        let int = |lo: i64, hi: i64| match value {
            ParamValue::Int(v) if (lo..=hi).contains(&v) => Ok(v),
            _ => Err(wrong(&format!("an integer from {lo} to {hi}"))),
        };
        let vec3 = || match value {
            ParamValue::Vec3(v) | ParamValue::Rgb(v) if v.iter().all(|c| c.is_finite()) => Ok(v),
            _ => Err(wrong("three finite numbers")),
        };
        let float = |ok: &dyn Fn(f32) -> bool, expected: &str| match value {
            ParamValue::Float(v) if ok(v) => Ok(v),
            ParamValue::Int(v) if ok(v as f32) => Ok(v as f32),
            _ => Err(wrong(expected)),
        };
        let depth = |v: i64| u32::try_from(v).ok();
        let d = &mut self.desc;
        match key {
            "spp" => d.spp = int(1, u32::MAX.into())? as u32,
            "seed" => self.seed = int(0, u32::MAX.into())? as u32,
            "max_depth" => {
                d.integrator.max_depth = depth(int(-1, u32::MAX.into())?);
                self.path = volpt_render::path_settings(d).with_choices_of(&self.path);
            }
            "rr_depth" => {
                d.integrator.rr_depth = depth(int(-1, u32::MAX.into())?);
                self.path = volpt_render::path_settings(d).with_choices_of(&self.path);
            }
            "camera.origin" | "camera.target" | "camera.up" => {
                let value = vec3()?;
                let (mut origin, mut target, mut up) = self.look_at();
                match key {
                    "camera.origin" => {
                        // Moving the camera keeps its direction.
                        let forward = [0, 1, 2].map(|i| target[i] - origin[i]);
                        origin = value;
                        target = [0, 1, 2].map(|i| origin[i] + forward[i]);
                    }
                    "camera.target" => target = value,
                    _ => up = value,
                }
                self.up = up;
                let before = self.desc.camera.to_world;
                let mut to_world = look_at(origin, target, up).ok_or_else(|| {
                    wrong("a camera whose direction (target - origin) and up are non-zero and not parallel")
                })?;
                // An orthographic film's extent is its frame's scale: moving it keeps that.
                if self.desc.camera.projection == volpt_scene::description::Projection::Orthographic
                {
                    for j in 0..3 {
                        let scale = (0..3).map(|i| before[i][j].powi(2)).sum::<f32>().sqrt();
                        (0..3).for_each(|i| to_world[i][j] *= scale);
                    }
                }
                self.desc.camera.to_world = to_world;
            }
            "camera.fov"
                if d.camera.projection == volpt_scene::description::Projection::Orthographic =>
            {
                return Err(wrong("no field of view: the camera is orthographic (its to_world scale sets the extent)"));
            }
            "camera.fov" => {
                d.camera.fov_degrees = float(&|v| v > 0.0 && v < 180.0, "degrees in (0, 180)")?
            }
            _ if LightsDesc::PARAMS.iter().any(|&(k, _)| k == key) => {
                // Present, as `get` says; the values are checked with the scene (`validate`).
                self.get(key)?;
                let l = &mut self.desc.lights;
                match (key, &mut l.sun, &mut l.spot) {
                    ("sun.direction", Some(s), _) => s.direction = vec3()?,
                    ("sun.irradiance", Some(s), _) => s.irradiance = vec3()?,
                    ("sun.angular_radius", Some(s), _) => {
                        s.angular_radius =
                            float(&|v| (0.0..=90.0).contains(&v), "degrees in [0, 90]")?
                    }
                    ("light.position", _, Some(s)) => s.position = vec3()?,
                    ("light.intensity", _, Some(s)) => s.intensity = vec3()?,
                    (_, _, Some(s)) => {
                        if let Some(cone) = &mut s.cone {
                            cone.direction = vec3()?;
                        }
                    }
                    _ => {}
                }
            }
            _ if MediumDesc::PARAMS.iter().any(|&(k, _)| k == key)
                || d.medium.material_params().iter().any(|(k, _)| k == key) =>
            {
                let medium = match value {
                    ParamValue::Int(v) => MediumParam::Float(v as f32),
                    ParamValue::Float(v) => MediumParam::Float(v),
                    ParamValue::Rgb(v) | ParamValue::Vec3(v) => MediumParam::Rgb(v),
                };
                if let Some(Err(refused)) = d.medium.set_param(key, medium) {
                    return Err(refusal(key, refused, &format!("{value:?}")));
                }
            }
            _ => {
                let Some(number) = PhaseDesc::PARAMS.iter().find(|p| p.key == key) else {
                    return Err(unknown(key));
                };
                let value = float(&number.accepts, number.expected)?;
                d.medium.phase.set_param(key, value);
            }
        }
        Ok(())
    }

    /// The scene checked as a loaded one is, its data's values as found when it was loaded.
    fn validate(&self) -> Result<(), volpt_scene::SceneError> {
        volpt_scene::validate::validate_settings(&self.desc, &self.source, self.data.checked)
    }

    /// What a renderer keeps of this scene between renders: the factory's scans of its grids,
    /// and the number naming its grids' values (unique to this scene's current grids: cloning a
    /// scene or replacing a grid's values names them anew, [`Scene::set_grid`]).
    pub(crate) fn kept_data(&self) -> (&FactoryCache, u64) {
        (&self.data.factory, self.data.id)
    }

    /// The medium's grid `name` (`"density"`, `"albedo"`: [`Scene::grid_names`]): its resolution,
    /// channels, box and values (x fastest, then y, then z, channels interleaved).
    pub fn grid(&self, name: &str) -> Result<&GridDesc, Error> {
        match self.desc.medium.grids().find(|(n, _)| *n == name) {
            Some((_, grid)) => Ok(grid),
            None => Err(self.no_grid(name)),
        }
    }

    /// The names of the medium's grids, in [`Scene::grid`]'s spelling.
    pub fn grid_names(&self) -> Vec<&'static str> {
        self.desc.medium.grids().map(|(name, _)| name).collect()
    }

    /// Replaces the values of the medium's grid `name` with `values`, laid out as the grid's
    /// own ([`Scene::grid`]: the same resolution and channels, x fastest), checked as a loaded
    /// scene's are. New values are new data: the scene's fingerprint, the backends' kept copies
    /// (the factory's scans, a GPU's resident grids, `auto`'s calibration key) follow them, and
    /// renders give the image of a scene loaded with them. Values equal to the grid's own, bit
    /// for bit, change nothing (every kept copy stays). A refusal (no such grid, a grid kept
    /// sparse, the wrong number of values, a value out of range) leaves the scene as it was.
    pub fn set_grid(&mut self, name: &str, values: Vec<f32>) -> Result<(), Error> {
        let grid = self.grid(name)?;
        let wrong = |expected: String, found: String| Error::Grid {
            grid: name.to_owned(),
            expected,
            found,
        };
        if grid.layout == SampleLayout::Sparse {
            return Err(wrong(
                "a dense grid (its values replaced in place)".into(),
                "a grid kept sparse (a VDB's leaves): load it dense (sparse = \"never\" in a \
                 TOML scene) to replace its values"
                    .into(),
            ));
        }
        let [x, y, z] = grid.resolution;
        if values.len() != grid.data.len() {
            return Err(wrong(
                format!(
                    "{} values ({x} x {y} x {z} samples x {} channels)",
                    grid.data.len(),
                    grid.channels
                ),
                format!("{} values", values.len()),
            ));
        }
        let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(a, b)| a.to_bits() == b.to_bits());
        if same(&grid.data, &values) {
            return Ok(());
        }
        let old = std::mem::replace(self.grid_values(name), values);
        self.renew_data(name, |scene| *scene.grid_values(name) = old)
    }

    /// Replaces the material index of every voxel of the medium's material-indexed volume
    /// ([`volpt_scene::material::IndexedDesc::set_indices`]: one per voxel, x fastest, bytes or
    /// `u16`s, each below the table's length) — a printing application's next iteration. New
    /// indices are new data, as [`Scene::set_grid`]'s new values are; the same indices change
    /// nothing; a refusal (a medium without indices, the wrong count, an index past the table)
    /// leaves the scene as it was.
    pub fn set_indices<I: volpt_scene::material::MaterialIndex>(
        &mut self,
        indices: &[I],
    ) -> Result<(), Error> {
        let DensityDesc::Indexed(volume) = &mut self.desc.medium.density else {
            return Err(Error::Grid {
                grid: "indices".to_owned(),
                expected: "a material-indexed medium".to_owned(),
                found: "a medium without material indices".to_owned(),
            });
        };
        let old = volume.clone();
        volume
            .set_indices(indices)
            .map_err(|problem| volpt_scene::SceneError::Material {
                path: self.source.clone().into(),
                problem,
            })?;
        if *volume == old {
            return Ok(());
        }
        self.renew_data("indices", |scene| {
            scene.desc.medium.density = DensityDesc::Indexed(old);
        })
    }

    /// Checks the scene after grid `name`'s data changed, as a loaded scene's are: if it passes,
    /// the data is new (its own identity: nothing kept of the old data is read again), else
    /// `restore` puts the old data back and the check's error names the grid.
    fn renew_data(&mut self, name: &str, restore: impl FnOnce(&mut Self)) -> Result<(), Error> {
        let checked = volpt_scene::validate::validate(&self.desc, &self.source)
            .map_err(|error| match error {
                volpt_scene::SceneError::InvalidScene {
                    field,
                    expected,
                    found,
                    ..
                } => Error::Grid {
                    grid: name.to_owned(),
                    expected: format!("{expected} (the scene's {field})"),
                    found,
                },
                error => Error::Scene(error),
            })
            .and_then(|checked| {
                check_lookup(&self.desc, self.desc.medium.lookup, checked).map(|()| checked)
            });
        match checked {
            Ok(checked) => {
                self.data = Arc::new(DataFacts::new(checked));
                self.changed();
                Ok(())
            }
            Err(error) => {
                restore(self);
                Err(error)
            }
        }
    }

    /// [`Scene::set_grid`] by value, for a chain of calls.
    pub fn with_grid(mut self, name: &str, values: Vec<f32>) -> Result<Self, Error> {
        self.set_grid(name, values)?;
        Ok(self)
    }

    /// The values of grid `name`, which [`Scene::grid`] found.
    fn grid_values(&mut self, name: &str) -> &mut Vec<f32> {
        let medium = &mut self.desc.medium;
        match (name, &mut medium.density, &mut medium.albedo) {
            ("density", DensityDesc::Grid(grid), _) | ("albedo", _, AlbedoDesc::Grid(grid)) => {
                &mut grid.data
            }
            _ => unreachable!("grid {name} was found by Scene::grid"),
        }
    }

    fn no_grid(&self, name: &str) -> Error {
        let names = self.grid_names();
        Error::Grid {
            grid: name.to_owned(),
            expected: if names.is_empty() {
                "a grid of the medium, which has none (its density and albedo are constants)".into()
            } else {
                format!("one of the medium's grids: {}", names.join(", "))
            },
            found: "no such grid".into(),
        }
    }

    /// The small parts [`Scene::set`] changes (never the grids), to restore on a refusal.
    fn clone_light(&self) -> Light {
        let d = &self.desc;
        Light {
            camera: d.camera,
            spp: d.spp,
            integrator: d.integrator,
            medium: MediumDesc::PARAMS
                .iter()
                .map(|&(key, _)| key.to_owned())
                .chain(d.medium.material_params().into_iter().map(|(key, _)| key))
                .filter_map(|key| {
                    let value = d.medium.param(&key)?.ok()?;
                    Some((key, value))
                })
                .collect(),
            phase: d.medium.phase,
            lights: d.lights,
            path: self.path,
            seed: self.seed,
            up: self.up,
        }
    }

    fn restore_light(&mut self, l: Light) {
        let d = &mut self.desc;
        d.camera = l.camera;
        d.spp = l.spp;
        d.integrator = l.integrator;
        for (key, value) in l.medium {
            // Each value was the medium's own, which its parameter takes.
            let _ = d.medium.set_param(&key, value);
        }
        d.medium.phase = l.phase;
        d.lights = l.lights;
        self.path = l.path;
        self.seed = l.seed;
        self.up = l.up;
    }
}

struct Light {
    camera: volpt_scene::CameraDesc,
    spp: u32,
    integrator: volpt_scene::IntegratorDesc,
    /// The medium's parameters that it has ([`MediumDesc::param`]), its materials' included.
    medium: Vec<(String, MediumParam)>,
    phase: PhaseDesc,
    lights: LightsDesc,
    path: PathSettings,
    seed: u32,
    up: [f32; 3],
}

/// The path settings of a changed integrator with the tracking, estimator and roulette chosen
/// before.
trait WithChoices {
    fn with_choices_of(self, chosen: &PathSettings) -> PathSettings;
}

impl WithChoices for PathSettings {
    fn with_choices_of(self, chosen: &PathSettings) -> PathSettings {
        PathSettings {
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            ..*chosen
        }
    }
}

fn unknown(key: &str) -> Error {
    let keys: Vec<_> = PARAMS.iter().map(|(k, _)| *k).collect();
    Error::UnknownParam {
        key: key.to_owned(),
        expected: format!("one of {}", keys.join(", ")),
    }
}

/// The error of a parameter the medium refuses; `value` is the value given, as the error shows it.
fn refusal(key: &str, refused: ParamRefused, value: &str) -> Error {
    let (expected, found) = match refused {
        ParamRefused::NotHere { needs, found } => (needs, found),
        ParamRefused::Value(expected) => (expected, value),
    };
    Error::Param {
        key: key.to_owned(),
        expected: expected.to_owned(),
        found: found.to_owned(),
    }
}

/// Refuses `lookup` where the medium's grids cannot take it: textures hold dense grids, and
/// half-precision texels end at 65504.
fn check_lookup(
    desc: &SceneDescription,
    lookup: GridLookup,
    checked: CheckedData,
) -> Result<(), Error> {
    let texture = matches!(lookup, GridLookup::Texture | GridLookup::TextureHalf);
    let sparse = (desc.medium.grids()).any(|(_, g)| g.layout == SampleLayout::Sparse);
    if texture && sparse {
        return Err(Error::Setting {
            key: GridLookup::KEY,
            expected: "a lookup of sparse grids for this scene's grid, kept sparse (a VDB): \
                       trilinear, stochastic or nearest (textures hold dense grids; a TOML scene \
                       reads a VDB dense with sparse = \"never\")"
                .to_owned(),
            found: lookup.name().to_owned(),
        });
    }
    if lookup != GridLookup::TextureHalf {
        return Ok(());
    }
    for (name, largest) in desc.medium.largest_values(checked) {
        if largest > HALF_MAX {
            return Err(Error::Setting {
                key: GridLookup::KEY,
                expected: format!(
                    "a lookup that holds the medium's largest {name}, {largest}: texture (f32 \
                     texels), not texture-f16, whose largest value is {HALF_MAX}"
                ),
                found: lookup.name().to_owned(),
            });
        }
    }
    Ok(())
}
