//! An edit of a material's 7 attributes (§5.1): each of diffuse albedo, specular albedo and
//! roughness is left alone, set, or scaled. [`Edit::apply`] checks the result (albedos in
//! [0, 1], roughness in the attribute model's range) and names what is wrong.

use crate::attributes::{Attributes, MAX_ROUGHNESS, MIN_ROUGHNESS};
use crate::error::{EvalError, Result};

/// A change of an RGB albedo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColourEdit {
    /// Set to these values (each in [0, 1]).
    Set([f64; 3]),
    /// Multiply every channel by this (>= 0).
    Scale(f64),
}

/// A change of the roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScalarEdit {
    /// Set to this GGX alpha (> 0).
    Set(f64),
    /// Multiply by this (> 0).
    Scale(f64),
}

impl ColourEdit {
    /// The edit of an attribute given either as values to set or as a scale (a command's or
    /// an API's two options for it): `None` for neither, an error naming `name` for both.
    pub fn set_or_scale(
        name: &str,
        set: Option<[f64; 3]>,
        scale: Option<f64>,
    ) -> Result<Option<Self>> {
        set_or_scale(name, set, scale, Self::Set, Self::Scale)
    }
}

impl ScalarEdit {
    /// [`ColourEdit::set_or_scale`] for the roughness.
    pub fn set_or_scale(name: &str, set: Option<f64>, scale: Option<f64>) -> Result<Option<Self>> {
        set_or_scale(name, set, scale, Self::Set, Self::Scale)
    }
}

fn set_or_scale<T, E>(
    name: &str,
    set: Option<T>,
    scale: Option<f64>,
    to_set: impl FnOnce(T) -> E,
    to_scale: impl FnOnce(f64) -> E,
) -> Result<Option<E>> {
    match (set, scale) {
        (Some(_), Some(_)) => {
            Err(EvalError::Invalid(format!("give {name} or {name}_scale, not both")))
        }
        (Some(v), None) => Ok(Some(to_set(v))),
        (None, Some(s)) => Ok(Some(to_scale(s))),
        (None, None) => Ok(None),
    }
}

/// Which attribute an edit changes (for the measures: the others should not move).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EditedAttribute {
    Diffuse,
    Specular,
    Roughness,
    /// No change (the identity edit).
    None,
}

/// An albedo below this in every channel is none, for [`Edit::without_effect`].
pub const NO_ALBEDO: f64 = 1e-3;

/// The edit of a material: `None` leaves an attribute as it is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Edit {
    pub diffuse: Option<ColourEdit>,
    pub specular: Option<ColourEdit>,
    pub roughness: Option<ScalarEdit>,
}

fn colour(name: &str, old: [f64; 3], edit: Option<ColourEdit>) -> Result<[f64; 3]> {
    let new = match edit {
        None => return Ok(old),
        Some(ColourEdit::Set(v)) => v,
        Some(ColourEdit::Scale(s)) => {
            if !(s.is_finite() && s >= 0.0) {
                return Err(EvalError::Invalid(format!(
                    "{name} albedo scale {s} must be a finite number >= 0"
                )));
            }
            old.map(|v| v * s)
        }
    };
    for (c, v) in ["R", "G", "B"].iter().zip(new) {
        if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
            return Err(EvalError::Invalid(format!(
                "{name} albedo {c} = {v:.4} is outside [0, 1] (an albedo is a fraction of the \
                 light; the material's is {:.4} {:.4} {:.4})",
                old[0], old[1], old[2]
            )));
        }
    }
    Ok(new)
}

impl Edit {
    /// The attribute this edit changes: the only one it touches, else `None` for the identity
    /// edit; an edit of several attributes reports the first of diffuse, specular, roughness.
    pub fn edited(&self) -> EditedAttribute {
        match (self.diffuse, self.specular, self.roughness) {
            (Some(_), _, _) => EditedAttribute::Diffuse,
            (None, Some(_), _) => EditedAttribute::Specular,
            (None, None, Some(_)) => EditedAttribute::Roughness,
            (None, None, None) => EditedAttribute::None,
        }
    }

    /// The recolour of the editing suites: the diffuse albedo `diffuse`'s channels rotated (red
    /// takes blue's value, green red's, blue green's), a change of hue at the same values.
    pub fn rotated_diffuse(diffuse: [f64; 3]) -> Self {
        Self {
            diffuse: Some(ColourEdit::Set([diffuse[2], diffuse[0], diffuse[1]])),
            ..Self::default()
        }
    }

    /// What of this edit cannot change `a`, in words: scaling an albedo the fit finds none of
    /// (every channel below [`NO_ALBEDO`]) leaves it at nothing, though a person may see a
    /// glow they would call that albedo (a broad lobe the fit took as specular). Empty when
    /// every part of the edit acts.
    pub fn without_effect(&self, a: &Attributes) -> Vec<String> {
        [("diffuse", a.diffuse, self.diffuse), ("specular", a.specular, self.specular)]
            .into_iter()
            .filter_map(|(name, old, edit)| match edit {
                Some(ColourEdit::Scale(s)) if s != 1.0 && old.iter().all(|&v| v < NO_ALBEDO) => {
                    Some(format!(
                        "the fit finds no {name} albedo ({:.4} {:.4} {:.4}), so scaling it \
                         changes nothing; set it to a colour instead",
                        old[0], old[1], old[2]
                    ))
                }
                _ => None,
            })
            .collect()
    }

    /// The edited attributes of `a`, checked.
    pub fn apply(&self, a: &Attributes) -> Result<Attributes> {
        let roughness = match self.roughness {
            None => a.roughness,
            Some(ScalarEdit::Set(r)) | Some(ScalarEdit::Scale(r))
                if !(r.is_finite() && r > 0.0) =>
            {
                return Err(EvalError::Invalid(format!(
                    "roughness {r} must be a positive number (a GGX alpha in \
                     [{MIN_ROUGHNESS}, {MAX_ROUGHNESS}], or a scale > 0)"
                )));
            }
            Some(ScalarEdit::Set(r)) => r,
            Some(ScalarEdit::Scale(s)) => a.roughness * s,
        };
        if !(MIN_ROUGHNESS..=MAX_ROUGHNESS).contains(&roughness) {
            return Err(EvalError::Invalid(format!(
                "roughness {roughness:.4} is outside [{MIN_ROUGHNESS}, {MAX_ROUGHNESS}] (the \
                 material's is {:.4})",
                a.roughness
            )));
        }
        let edited = Attributes {
            diffuse: colour("diffuse", a.diffuse, self.diffuse)?,
            specular: colour("specular", a.specular, self.specular)?,
            roughness,
        };
        edited.validate()?;
        Ok(edited)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_an_albedo_the_fit_lacks_is_named() {
        let metal = Attributes { diffuse: [0.0; 3], specular: [0.5, 0.4, 0.2], roughness: 0.1 };
        let halve = Edit { diffuse: Some(ColourEdit::Scale(0.5)), ..Edit::default() };
        let notes = halve.without_effect(&metal);
        assert_eq!(notes.len(), 1);
        assert!(notes[0].contains("no diffuse albedo"), "{notes:?}");
        // Setting it acts; scaling the specular acts; a plastic's diffuse acts.
        let set = Edit { diffuse: Some(ColourEdit::Set([0.2; 3])), ..Edit::default() };
        assert!(set.without_effect(&metal).is_empty());
        let spec = Edit { specular: Some(ColourEdit::Scale(0.5)), ..Edit::default() };
        assert!(spec.without_effect(&metal).is_empty());
        let plastic = Attributes { diffuse: [0.3, 0.1, 0.1], ..metal };
        assert!(halve.without_effect(&plastic).is_empty());
    }

    #[test]
    fn an_attribute_is_set_or_scaled_not_both() {
        let set = ColourEdit::set_or_scale("diffuse", Some([0.1, 0.2, 0.3]), None).unwrap();
        assert_eq!(set, Some(ColourEdit::Set([0.1, 0.2, 0.3])));
        assert_eq!(
            ColourEdit::set_or_scale("diffuse", None, Some(2.0)).unwrap(),
            Some(ColourEdit::Scale(2.0))
        );
        assert_eq!(ScalarEdit::set_or_scale("roughness", None, None).unwrap(), None);
        assert_eq!(
            ScalarEdit::set_or_scale("roughness", Some(0.2), None).unwrap(),
            Some(ScalarEdit::Set(0.2))
        );
        let both = ScalarEdit::set_or_scale("roughness", Some(0.2), Some(2.0)).unwrap_err();
        assert!(both.to_string().contains("give roughness or roughness_scale, not both"), "{both}");
    }

    #[test]
    fn edits_apply_and_bad_values_are_named() {
        let a = Attributes { diffuse: [0.4, 0.2, 0.1], specular: [0.05; 3], roughness: 0.1 };
        let e = Edit { diffuse: Some(ColourEdit::Scale(0.5)), ..Edit::default() };
        assert_eq!(e.apply(&a).unwrap().diffuse, [0.2, 0.1, 0.05]);
        assert_eq!(e.edited(), EditedAttribute::Diffuse);
        assert_eq!(Edit::default().apply(&a).unwrap(), a);
        assert_eq!(Edit::default().edited(), EditedAttribute::None);
        let e = Edit { roughness: Some(ScalarEdit::Scale(2.0)), ..Edit::default() };
        assert!((e.apply(&a).unwrap().roughness - 0.2).abs() < 1e-12);
        let cases = [
            (Edit { diffuse: Some(ColourEdit::Scale(3.0)), ..Edit::default() }, "diffuse albedo R"),
            (
                Edit { specular: Some(ColourEdit::Set([0.1, 1.5, 0.1])), ..Edit::default() },
                "specular albedo G",
            ),
            (Edit { diffuse: Some(ColourEdit::Scale(-1.0)), ..Edit::default() }, ">= 0"),
            (Edit { roughness: Some(ScalarEdit::Set(-0.2)), ..Edit::default() }, "positive"),
            (Edit { roughness: Some(ScalarEdit::Scale(20.0)), ..Edit::default() }, "outside"),
            (Edit { roughness: Some(ScalarEdit::Set(f64::NAN)), ..Edit::default() }, "roughness"),
        ];
        for (edit, needle) in cases {
            let err = edit.apply(&a).unwrap_err().to_string();
            assert!(err.contains(needle), "{needle}: {err}");
        }
    }
}
