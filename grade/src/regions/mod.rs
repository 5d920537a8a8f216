//! Solution regions: found in the source as Rust tokens ([`lexer`], [`markers`]), turned into
//! the starter's stubs ([`stub`]), checked against the allow list before a line of a student's is
//! built ([`allow`]), and compared with the starter the student was given ([`baseline`]).

pub mod allow;
pub mod baseline;
pub mod lexer;
pub mod markers;
pub mod stub;
