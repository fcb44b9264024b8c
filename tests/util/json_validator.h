// A strict JSON validator (RFC 8259) for the tests of the program's --json
// files.

#ifndef CERES_SESYNC_TESTS_UTIL_JSON_VALIDATOR_H_
#define CERES_SESYNC_TESTS_UTIL_JSON_VALIDATOR_H_

#include <string>

namespace ceres_sesync::test_util {

// True if `text` is one valid JSON document.
bool IsValidJson(const std::string& text);

}  // namespace ceres_sesync::test_util

#endif  // CERES_SESYNC_TESTS_UTIL_JSON_VALIDATOR_H_
