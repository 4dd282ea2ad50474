//! The command-line names of the renderer's option enums (`--renderer`,
//! `--light-culling`, `--shadows`, `--variants`): one macro gives each enum its
//! list of variants, its names and a `Display` that prints the name, so the four
//! enums cannot drift apart in how they are named and printed.

/// For `$ty { $variant => "name", ... }` (every unit variant of the enum, in
/// order): `$ty::ALL`, `$ty::name` and `Display`. With `parse = "message {}"`
/// also `FromStr` on exactly those names (`Err`: the message with the input).
macro_rules! cli_names {
    ($ty:ident { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl $ty {
            /// Every variant, in declaration order.
            pub const ALL: [$ty; [$($name),+].len()] = [$($ty::$variant),+];

            /// The command-line name.
            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name,)+
                }
            }
        }

        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
    ($ty:ident { $($body:tt)+ }, parse = $unknown:literal) => {
        cli_names!($ty { $($body)+ });

        impl std::str::FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                $ty::ALL
                    .into_iter()
                    .find(|v| v.name() == s)
                    .ok_or_else(|| format!($unknown, s))
            }
        }
    };
}

pub(crate) use cli_names;

#[cfg(test)]
mod tests {
    use crate::render::clusters::LightCulling;
    use crate::render::material::VariantMode;
    use crate::render::{ShadowMode, Technique};
    use std::fmt::{Debug, Display};
    use std::str::FromStr;

    /// Every variant's name parses back to it and is what it prints; `unknown` is
    /// refused with a message that names it.
    fn round_trip<T>(all: &[T], name: fn(T) -> &'static str, unknown: &str)
    where
        T: Copy + PartialEq + Debug + Display + FromStr<Err = String>,
    {
        for &v in all {
            assert_eq!(name(v).parse::<T>(), Ok(v));
            assert_eq!(v.to_string(), name(v));
        }
        let err = unknown.parse::<T>().unwrap_err();
        assert!(err.contains(unknown), "{err}");
    }

    #[test]
    fn names_parse_and_print() {
        round_trip(&Technique::ALL, Technique::name, "tiled");
        round_trip(&VariantMode::ALL, VariantMode::name, "fast");
        round_trip(&LightCulling::ALL, LightCulling::name, "tiles");
        round_trip(&ShadowMode::ALL, ShadowMode::name, "soft");
    }
}
