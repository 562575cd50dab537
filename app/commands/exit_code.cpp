#include "app/commands/commands.h"

namespace mmm::app {
namespace {

int& requested_exit_code() {
  static int code = 0;
  return code;
}

}  // namespace

int exit_code() { return requested_exit_code(); }
void set_exit_code(int code) { requested_exit_code() = code; }

}  // namespace mmm::app
