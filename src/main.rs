fn main() {
    server::run()
}
