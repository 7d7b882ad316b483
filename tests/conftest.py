def pytest_configure(config):
    # `bash scripts/test.sh` leaves these out; `bash scripts/test.sh --all` (what .ci/run runs) takes them.
    config.addinivalue_line("markers", "slow: builds or runs for minutes (the profile-guided build); run with --all")
