# The fuzz harnesses, one source file each under tests/fuzz/: the libFuzzer build
# (tests/fuzz/CMakeLists.txt, scripts/fuzz.sh) and the unit tests' replay of their corpora
# (tests/CMakeLists.txt) build the same list.
set(PLCEMU_FUZZERS fuzz_tcp_request fuzz_rtu_frame fuzz_config fuzz_config_tree
                   fuzz_master_reply fuzz_fatek_frame fuzz_http_request fuzz_listing)
# The request harnesses hold every reply to libmodbus' (tests/support/modbus_oracle.hpp).
set(PLCEMU_ORACLE_FUZZERS fuzz_tcp_request fuzz_rtu_frame)
