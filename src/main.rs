fn main() { server::run() }
