// Why common/bus/CMakeLists.txt compiles bus.cpp with -fno-sanitize=vptr under GCC (not built
// by CMake; a reproducer for the record). lcm-cpp's LCMMHUntypedSubscription::cb_func calls the
// handler through a pointer to member function; GCC 12 with -fsanitize=vptr calls it with the
// wrong object (here: a vptr report on address 0x1, then SIGSEGV), clang 14 and GCC without
// the vptr check print n=1:
//   g++ -std=c++20 -O1 -g -fsanitize=address,undefined gcc_vptr_pmf.cpp -llcm && ./a.out      # fails
//   g++ -std=c++20 -O1 -g -fsanitize=address,undefined -fno-sanitize=vptr gcc_vptr_pmf.cpp -llcm  # n=1
//   clang++ -std=c++20 -O1 -g -fsanitize=address,undefined gcc_vptr_pmf.cpp -llcm              # n=1
#include <lcm/lcm-cpp.hpp>
#include <cstdio>
struct H { virtual ~H() {} int n = 0; void on(const lcm::ReceiveBuffer*, const std::string&) { ++n; } };
struct D : H {};
int main() {
  lcm::LCM l("memq://");
  D h;
  l.subscribe("A", &H::on, static_cast<H*>(&h));
  char b[4] = {1,2,3,4};
  l.publish("A", b, 4);
  l.handleTimeout(100);
  printf("n=%d\n", h.n);
}
