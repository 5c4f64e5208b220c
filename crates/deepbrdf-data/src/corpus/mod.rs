//! A corpus of physically based analytic materials with known parameters (a training set
//! that covers the space of materials between and beyond the measured ones, with the
//! answers of edits known): the models ([`diffuse`], [`microfacet`], [`fresnel`],
//! [`conductors`], [`sheen`], [`retro`], [`coat`]), the [`material`] description with its
//! known [`attributes`] and edits, the [`sampler`], tabulation on the MERL grid ([`tabulate`],
//! [`stream`]) and the compact corpus [`file`].
pub mod attributes;
#[cfg(test)]
pub(crate) mod checks;
pub mod coat;
pub mod conductors;
pub mod diffuse;
pub mod energy;
pub mod file;
pub mod fresnel;
pub mod material;
pub mod microfacet;
pub mod retro;
pub mod sampler;
pub mod sheen;
pub mod stream;
pub mod tabulate;

pub use attributes::KnownAttributes;
pub use file::{write_corpus, CorpusReader, Header, Record};
pub use material::{Family, Material};
pub use sampler::{sample, sample_family};
pub use stream::{sampled, tabulate_each};
pub use tabulate::tabulate;
