//! Names for option enums: what `[render] sampler = "sobol"` and `--sampler sobol` parse.

/// Gives a fieldless `Copy` enum its user-facing names: `ALL`, `name()`, `names()`,
/// `Display`, and a `FromStr` whose error lists the valid names,
/// "unknown <what> `x` (valid: a, b)".
///
/// ```
/// #[derive(Clone, Copy, Debug, PartialEq)]
/// enum Shade { Flat, Smooth }
/// raylab_core::named_enum!(Shade, "shading", { Flat => "flat", Smooth => "smooth" });
/// assert_eq!("smooth".parse::<Shade>(), Ok(Shade::Smooth));
/// assert_eq!("round".parse::<Shade>().unwrap_err(), "unknown shading `round` (valid: flat, smooth)");
/// ```
#[macro_export]
macro_rules! named_enum {
    ($ty:ident, $what:literal, { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl $ty {
            /// Every value, in the order of [`Self::names`].
            pub const ALL: &'static [$ty] = &[$($ty::$variant),+];

            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name),+
                }
            }

            /// The valid names, comma-separated.
            pub fn names() -> String {
                [$($name),+].join(", ")
            }
        }

        impl ::std::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::std::str::FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                Self::ALL.iter().copied().find(|v| v.name() == s).ok_or_else(|| format!("unknown {} `{s}` (valid: {})", $what, Self::names()))
            }
        }
    };
}
