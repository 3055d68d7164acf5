// The plain program that bench_startup measures the command line against: a C++ main that prints one
// line, linked with the C++ standard library only.
#include <iostream>

int main() {
  std::cout << "plain\n";
  return 0;
}
