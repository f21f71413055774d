//! Names for option enums: what `[render] sampler = "sobol"` and `--sampler sobol` parse.
//! Each enum lists its names once; `FromStr`, `Display` and clap's `ValueEnum` (the CLI's
//! possible values) all read that one list.

/// Gives a fieldless `Copy` enum its user-facing names: `ALL`, `name()`, `names()`,
/// `Display`, clap's `ValueEnum`, and a `FromStr` whose error lists the valid names,
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

        $crate::value_enum_from_names!($ty);
    };
}

/// Implements clap's `ValueEnum` from a type's `ALL` and `name()`, so that a command-line
/// flag accepts (and `--help` lists) exactly the names scene files accept. Crates using it
/// need no clap dependency of their own.
#[macro_export]
macro_rules! value_enum_from_names {
    ($ty:ty) => {
        impl $crate::__clap::ValueEnum for $ty {
            fn value_variants<'a>() -> &'a [Self] {
                Self::ALL
            }

            fn to_possible_value(&self) -> Option<$crate::__clap::builder::PossibleValue> {
                Some($crate::__clap::builder::PossibleValue::new(self.name()))
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use clap::ValueEnum;

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Shade {
        Flat,
        Smooth,
    }
    named_enum!(Shade, "shading", { Flat => "flat", Smooth => "smooth" });

    #[test]
    fn value_enum_accepts_the_same_names_as_from_str() {
        let names: Vec<String> = Shade::value_variants().iter().map(|v| v.to_possible_value().unwrap().get_name().to_string()).collect();
        assert_eq!(names, ["flat", "smooth"]);
        assert_eq!(<Shade as ValueEnum>::from_str("smooth", false), Ok(Shade::Smooth));
        assert!(<Shade as ValueEnum>::from_str("round", false).is_err());
    }
}
