//! For spot-nav's own tests, not part of the API: test data the repository has and the published
//! packages leave out.

/// Whether a test must skip because its data is not here: the folders given (relative to the
/// calling package) are in the spot-nav repository, and the published packages leave them out
/// (`exclude` in each manifest). There the test says what is missing on the terminal, past the
/// test harness's capture, and returns early; in the repository a missing folder fails it.
/// A macro so that `CARGO_MANIFEST_DIR` is the calling package's.
///
/// ```
/// fn a_test_on_bundled_data() {
///     // The calling package's folders: this one's `src/` is always there.
///     if slam_core::skip_without_test_data!("src") {
///         return;
///     }
///     assert!(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src").is_dir());
/// }
/// a_test_on_bundled_data();
/// ```
#[doc(hidden)]
#[macro_export]
macro_rules! skip_without_test_data {
    ($($dir:expr),+ $(,)?) => {{
        use ::std::io::Write as _;
        let package = ::std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let dirs: &[&str] = &[$($dir),+];
        match dirs.iter().map(|d| package.join(d)).find(|d| !d.is_dir()) {
            None => false,
            Some(missing) => {
                let in_repository = package.join("../.ci").is_dir();
                assert!(!in_repository, "test data {} is missing", missing.display());
                let test = ::std::thread::current().name().unwrap_or("a test").to_owned();
                let message = format!(
                    "SKIPPED {test}: {} is not in the published package (it is in the spot-nav \
                     repository)\n",
                    missing.display()
                );
                // Straight to the terminal: the harness captures `eprintln!` of a passing test.
                let _ = ::std::io::stderr().write_all(message.as_bytes());
                true
            }
        }
    }};
}
