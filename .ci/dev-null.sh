# Sourced by the CI scripts. `/dev/null` must be the null device: cargo feeds it to rustc as stdin
# when it probes the target, and build scripts send their own compiler probes' errors to it. On a
# machine where `/dev/null` had become a regular file, those errors accumulated in it and every
# cargo command after the first build failed with "failed to run `rustc` to learn about
# target-specific information" (and cargo cached that failure in target/.rustc_info.json).
#
# `ensure_dev_null` recreates the device when it can (as root), and otherwise empties the file and
# forgets cargo's cached probe, which is enough before each cargo command.
ensure_dev_null() {
    [ -c /dev/null ] && return 0
    echo "ci: /dev/null is not a character device; repairing it" >&2
    if [ "$(id -u)" = 0 ] && rm -f /dev/null && mknod -m 666 /dev/null c 1 3; then
        return 0
    fi
    : > /dev/null
    rm -f target/.rustc_info.json
}

# Runs one CI step after checking /dev/null.
step() {
    ensure_dev_null
    "$@"
}
