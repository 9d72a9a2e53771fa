//! The `pdeshape` command-line tool.

fn main() {
    println!("pdeshape");
}
