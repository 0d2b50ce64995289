//! granbed-cli placeholder.
fn main() {}
