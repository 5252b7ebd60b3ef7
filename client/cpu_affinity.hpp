#pragma once
// Pinning the load tester to CPUs, so that a sweep on one machine can keep it off the server's.
#include <string>
#include <vector>

namespace nidevo::client {

// "0", "0,2", "1-3", "0,2-3": the CPU numbers, sorted and unique. Throws std::invalid_argument
// naming the part that is not a CPU number or range.
std::vector<int> parseCpuList(const std::string& list);
// Pins the calling thread, and every thread it starts from then on, to `cpus`; called first
// thing in main, that is the whole process. Throws std::runtime_error
// with the system's reason when it cannot.
void pinProcessToCpus(const std::vector<int>& cpus);
// The CPUs this thread may run on, sorted.
std::vector<int> allowedCpus();
// "0,2-3" for {0, 2, 3}.
std::string formatCpuList(const std::vector<int>& cpus);
// User plus system CPU seconds this process has used.
double processCpuSeconds();

}  // namespace nidevo::client
