pub mod context;
pub mod executor;
pub mod runner;
pub mod stream;
pub mod sequence;
