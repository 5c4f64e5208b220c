//! The names of the workspace's fieldless enums (presets, measures, modes, devices), written
//! one way: [`named_enum!`].

/// Gives a fieldless enum its names, each variant with the one it has on the command line and
/// in files: `ALL` (every value, in the order listed), `name()`, `from_name()` (the value of a
/// name, ignoring surrounding white space and ASCII case) and `Display` as the name. `FromStr`
/// stays with the enum, whose error says in its own words what was expected.
///
/// ```
/// #[derive(Clone, Copy, Debug, PartialEq)]
/// enum Colour { Red, Green }
/// deepbrdf_data::named_enum!(Colour { Red => "red", Green => "green" });
/// assert_eq!(Colour::ALL, [Colour::Red, Colour::Green]);
/// assert_eq!(Colour::from_name(" Green"), Some(Colour::Green));
/// assert_eq!(Colour::Red.to_string(), "red");
/// ```
#[macro_export]
macro_rules! named_enum {
    ($ty:ident { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl $ty {
            /// Every value, in table order.
            pub const ALL: [$ty; [$($name),+].len()] = [$($ty::$variant),+];

            /// The name on the command line and in files.
            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name,)+
                }
            }

            /// The value called `name` (surrounding white space and ASCII case ignored).
            pub fn from_name(name: &str) -> Option<Self> {
                let name = name.trim();
                Self::ALL.into_iter().find(|v| v.name().eq_ignore_ascii_case(name))
            }
        }

        impl ::std::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}
