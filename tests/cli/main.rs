//! End-to-end tests of the `experiments` command line, compiled as one test binary.
mod util;

mod attributes;
mod baselines;
mod convert;
mod corpus;
mod data;
mod devices;
mod edit_known;
mod editing;
mod fetch_merl;
mod generalize;
mod kill;
mod mitsuba;
mod model;
mod quality;
mod recovery;
mod reliability;
mod render;
mod serve;
mod shipped;
mod sweep_k;
