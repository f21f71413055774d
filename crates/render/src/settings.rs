//! Render settings, defined once. One table below lists every setting with its type,
//! default, valid range and meaning; it generates [`RenderSettings`], the [`Overrides`] a
//! scene file, the command line or Python give (with their `apply`, `or` and `set`), and
//! [`SETTINGS`], the key list the scene reader, the CLI, the Python module and the docs'
//! `[render]` table are checked against. Named values (samplers, integrators, ...) take
//! their names from each enum's one list (`named_enum!`), which also gives clap's
//! `ValueEnum`.

use raylab_accel::{AccelKind, BuildOptions};

use crate::filter::PixelFilter;
use crate::integrator::kind::IntegratorKind;
use crate::integrator::mis::MisHeuristic;
use crate::light::{LightSampling, DEFAULT_CELLS, MAX_CELLS};
use crate::sampler::SamplerKind;

/// A setting's value as a scene file or a keyword argument writes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SettingValue<'a> {
    Integer(i128),
    Name(&'a str),
}

/// What values a setting takes.
#[derive(Clone, Copy, Debug)]
pub enum SettingKind {
    /// An integer in `min..=max`.
    Integer { min: u64, max: u64 },
    /// One of the names of an option enum; the function lists them, comma-separated.
    Name(fn() -> String),
}

/// One row of the settings table.
#[derive(Clone, Copy, Debug)]
pub struct SettingSpec {
    /// The key in scene files and Python keywords; the CLI flag is `--` + the key with `-` for `_`.
    pub key: &'static str,
    /// The scene-file table the key belongs to (`render`, or `camera` for the image size).
    pub table: &'static str,
    pub kind: SettingKind,
    /// The default as a scene file writes it (`640`, `"jittered"`).
    pub default: fn() -> String,
    pub doc: &'static str,
}

impl SettingSpec {
    /// The command-line flag that overrides this setting.
    pub fn flag(&self) -> String {
        format!("--{}", self.key.replace('_', "-"))
    }

    /// The `(min, max)` of an integer setting.
    pub fn range(&self) -> Option<(u64, u64)> {
        match self.kind {
            SettingKind::Integer { min, max } => Some((min, max)),
            SettingKind::Name(_) => None,
        }
    }
}

/// The settings table's row for `key`.
pub fn spec(key: &str) -> Option<&'static SettingSpec> {
    SETTINGS.iter().find(|s| s.key == key)
}

/// How each type of setting reads a [`SettingValue`] and describes itself.
pub trait SettingType: Sized + Copy {
    /// The valid names of a named setting, comma-separated (empty for integers).
    fn names() -> String;
    /// Parses `v`; the message says what was expected (`must be between 1 and 16384, found 0`).
    fn parse(v: SettingValue, min: u64, max: u64) -> Result<Self, String>;
    /// The value as a [`SettingValue`].
    fn value(self) -> SettingValue<'static>;
    /// The value as a scene file writes it.
    fn written(self) -> String {
        match self.value() {
            SettingValue::Integer(n) => n.to_string(),
            SettingValue::Name(s) => format!("\"{s}\""),
        }
    }
}

fn integer<T: TryFrom<i128>>(v: SettingValue, min: u64, max: u64) -> Result<T, String> {
    match v {
        SettingValue::Integer(n) if (min as i128..=max as i128).contains(&n) => T::try_from(n).map_err(|_| format!("must be between {min} and {max}, found {n}")),
        SettingValue::Integer(n) => Err(format!("must be between {min} and {max}, found {n}")),
        SettingValue::Name(s) => Err(format!("expected an integer, found the string \"{s}\"")),
    }
}

impl SettingType for u32 {
    fn names() -> String {
        String::new()
    }
    fn parse(v: SettingValue, min: u64, max: u64) -> Result<Self, String> {
        integer(v, min, max)
    }
    fn value(self) -> SettingValue<'static> {
        SettingValue::Integer(self as i128)
    }
}

impl SettingType for u64 {
    fn names() -> String {
        String::new()
    }
    fn parse(v: SettingValue, min: u64, max: u64) -> Result<Self, String> {
        integer(v, min, max)
    }
    fn value(self) -> SettingValue<'static> {
        SettingValue::Integer(self as i128)
    }
}

/// Named settings parse by the enum's `FromStr`, whose error lists the valid names.
macro_rules! named_settings {
    ($($ty:ty),+) => {$(
        impl SettingType for $ty {
            fn names() -> String {
                <$ty>::names()
            }
            fn parse(v: SettingValue, _: u64, _: u64) -> Result<Self, String> {
                match v {
                    SettingValue::Name(s) => s.parse::<$ty>().map_err(|e| e.to_string()),
                    SettingValue::Integer(n) => Err(format!("expected a name (valid: {}), found {n}", <$ty>::names())),
                }
            }
            fn value(self) -> SettingValue<'static> {
                SettingValue::Name(self.name())
            }
        }
    )+};
}

named_settings!(SamplerKind, IntegratorKind, LightSampling, MisHeuristic, PixelFilter, AccelKind);

/// Generates the settings struct, the overrides, and the key table from one list.
macro_rules! render_settings {
    ($( $(#[doc = $doc:literal])+ [$table:literal] $key:ident: $ty:ty = $default:expr $(, $min:literal ..= $max:expr)?; )+) => {
        /// How to render: a scene's `[render]` table (and its image size), overridable from the
        /// command line and Python.
        #[derive(Clone, Debug, PartialEq)]
        pub struct RenderSettings {
            $( $(#[doc = $doc])+ pub $key: $ty, )+
        }

        impl Default for RenderSettings {
            fn default() -> Self {
                Self { $( $key: $default, )+ }
            }
        }

        impl RenderSettings {
            /// The value of the setting named `key` (a key of [`SETTINGS`]).
            pub fn get(&self, key: &str) -> Option<SettingValue<'static>> {
                match key {
                    $( stringify!($key) => Some(SettingType::value(self.$key)), )+
                    _ => None,
                }
            }
        }

        /// Values that replace the defaults: a scene file's own settings, then the command
        /// line's or Python's, each layered with [`Overrides::or`] and applied by
        /// [`Overrides::apply`]. Besides the table's settings, the acceleration structure's
        /// build options and the front ends' leniency.
        #[derive(Clone, Debug, Default)]
        pub struct Overrides {
            $( pub $key: Option<$ty>, )+
            /// Parameters of the acceleration structure's build (SAH costs, leaf size, bins, ...).
            pub build: Option<BuildOptions>,
            /// Front ends warn about and skip what they do not support instead of failing
            /// (pbrt-v4 directives outside raylab's subset).
            pub lenient: bool,
        }

        impl Overrides {
            /// Replaces the settings these overrides give.
            pub fn apply(&self, s: &mut RenderSettings) {
                $( if let Some(v) = self.$key { s.$key = v; } )+
            }

            /// The value these overrides give the setting named `key`, if they give one.
            pub fn get(&self, key: &str) -> Option<SettingValue<'static>> {
                match key {
                    $( stringify!($key) => self.$key.map(SettingType::value), )+
                    _ => None,
                }
            }

            /// These overrides on top of `earlier`: the values these set win.
            pub fn or(&self, earlier: &Overrides) -> Overrides {
                Overrides {
                    $( $key: self.$key.or(earlier.$key), )+
                    build: self.build.clone().or_else(|| earlier.build.clone()),
                    lenient: self.lenient || earlier.lenient,
                }
            }

            /// Sets the setting named `key` (a key of [`SETTINGS`]) from a scene file's or a
            /// keyword's value; the error says what the setting takes.
            pub fn set(&mut self, key: &str, v: SettingValue) -> Result<(), String> {
                match key {
                    $( stringify!($key) => {
                        let (min, max) = render_settings!(@range $($min, $max)?);
                        self.$key = Some(<$ty as SettingType>::parse(v, min, max)?);
                    } )+
                    _ => return Err(format!("unknown setting `{key}` (valid: {})", SETTINGS.iter().map(|s| s.key).collect::<Vec<_>>().join(", "))),
                }
                Ok(())
            }
        }

        /// Every setting, in the order of the docs' `[render]` table.
        pub const SETTINGS: &[SettingSpec] = &[
            $( SettingSpec {
                key: stringify!($key),
                table: $table,
                kind: {
                    let (min, max) = render_settings!(@range $($min, $max)?);
                    if render_settings!(@ranged $($min)?) { SettingKind::Integer { min, max } } else { SettingKind::Name(<$ty as SettingType>::names) }
                },
                default: || <$ty as SettingType>::written($default),
                doc: concat!($($doc),+),
            }, )+
        ];
    };
    (@range $min:literal, $max:expr) => { ($min as u64, $max as u64) };
    (@range) => { (0u64, 0u64) };
    (@ranged $min:literal) => { true };
    (@ranged) => { false };
}

render_settings! {
    /// Image width in pixels.
    ["camera"] width: u32 = 640, 1 ..= 16384;
    /// Image height in pixels.
    ["camera"] height: u32 = 480, 1 ..= 16384;
    /// Samples per pixel; the jittered sampler rounds a non-square count up to the next square.
    ["render"] spp: u32 = 4, 1 ..= 1048576;
    /// Pixel sampler.
    ["render"] sampler: SamplerKind = SamplerKind::Jittered;
    /// Maximum number of path segments from the camera (1 = only what the camera sees).
    ["render"] max_depth: u32 = 8, 1 ..= 1024;
    /// Integrator: lighting, an AOV, or a statistics view.
    ["render"] integrator: IntegratorKind = IntegratorKind::Whitted;
    /// How `direct` and `path` sample area lights.
    ["render"] light_sampling: LightSampling = LightSampling::Mis;
    /// How `mis` weighs light and BSDF samples.
    ["render"] mis_heuristic: MisHeuristic = MisHeuristic::Power;
    /// Cells per side of the `cells` strategy's grid (read by `Scene::build_accel`).
    ["render"] light_cells: u32 = DEFAULT_CELLS, 1 ..= MAX_CELLS;
    /// Acceleration structure.
    ["render"] accel: AccelKind = AccelKind::Bvh8;
    /// Pixel reconstruction filter.
    ["render"] filter: PixelFilter = PixelFilter::Box;
    /// Seed of the per-pixel random streams.
    ["render"] seed: u64 = 0, 0 ..= u64::MAX;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_lists_every_field_with_its_default() {
        let keys: Vec<&str> = SETTINGS.iter().map(|s| s.key).collect();
        assert_eq!(keys, ["width", "height", "spp", "sampler", "max_depth", "integrator", "light_sampling", "mis_heuristic", "light_cells", "accel", "filter", "seed"]);
        let d = RenderSettings::default();
        assert_eq!((d.width, d.height, d.spp, d.max_depth, d.light_cells, d.seed), (640, 480, 4, 8, 8, 0));
        assert_eq!((spec("spp").unwrap().default)(), "4");
        assert_eq!((spec("accel").unwrap().default)(), "\"bvh8\"");
        assert_eq!(spec("light_cells").unwrap().range(), Some((1, 16)));
        assert_eq!(spec("sampler").unwrap().range(), None);
        assert_eq!(spec("max_depth").unwrap().flag(), "--max-depth");
        let SettingKind::Name(names) = spec("filter").unwrap().kind else { panic!("filter is named") };
        assert_eq!(names(), "box, tent, gaussian");
        assert_eq!(d.get("sampler"), Some(SettingValue::Name("jittered")));
        assert_eq!(d.get("height"), Some(SettingValue::Integer(480)));
        assert_eq!(d.get("colour"), None);
    }

    #[test]
    fn set_parses_checks_and_names_the_valid_values() {
        let mut o = Overrides::default();
        o.set("spp", SettingValue::Integer(16)).unwrap();
        o.set("sampler", SettingValue::Name("sobol")).unwrap();
        o.set("accel", SettingValue::Name("kdtree")).unwrap();
        assert_eq!((o.spp, o.sampler, o.accel), (Some(16), Some(SamplerKind::Sobol), Some(AccelKind::KdTree)));
        assert_eq!(o.set("spp", SettingValue::Integer(0)), Err("must be between 1 and 1048576, found 0".into()));
        assert_eq!(o.set("light_cells", SettingValue::Integer(17)), Err("must be between 1 and 16, found 17".into()));
        assert_eq!(o.set("sampler", SettingValue::Name("halton")), Err("unknown sampler `halton` (valid: random, jittered, sobol)".into()));
        assert_eq!(o.set("filter", SettingValue::Integer(2)), Err("expected a name (valid: box, tent, gaussian), found 2".into()));
        assert_eq!(o.set("width", SettingValue::Name("wide")), Err("expected an integer, found the string \"wide\"".into()));
        assert!(o.set("colour", SettingValue::Integer(1)).unwrap_err().starts_with("unknown setting `colour` (valid: width, height, spp, "));
    }

    #[test]
    fn later_overrides_win_and_apply_replaces_only_what_they_give() {
        let file = Overrides { spp: Some(16), seed: Some(3), ..Default::default() };
        let cli = Overrides { spp: Some(64), accel: Some(AccelKind::Grid), lenient: true, ..Default::default() };
        let o = cli.or(&file);
        let mut s = RenderSettings::default();
        o.apply(&mut s);
        assert_eq!(s, RenderSettings { spp: 64, seed: 3, accel: AccelKind::Grid, ..Default::default() });
        assert!(o.lenient);
    }
}
