// A Google Benchmark reporter that forwards to the one the flags ask for
// (console, or JSON with --benchmark_format=json) while letting a benchmark
// keep the figures it prints ratios from. Subclasses read each run in
// keep(); everything else goes straight to the inner reporter.
#pragma once

#include <benchmark/benchmark.h>

#include <unistd.h>
#include <iostream>
#include <memory>
#include <vector>

namespace tonus::bench {

class ForwardingReporter : public benchmark::BenchmarkReporter {
 public:
  explicit ForwardingReporter(bool json) {
    if (json) {
      inner_ = std::make_unique<benchmark::JSONReporter>();
    } else {
      inner_ = std::make_unique<benchmark::ConsoleReporter>(isatty(STDOUT_FILENO) != 0
                                                                ? benchmark::ConsoleReporter::OO_ColorTabular
                                                                : benchmark::ConsoleReporter::OO_Tabular);
    }
    inner_->SetOutputStream(&std::cout);
    inner_->SetErrorStream(&std::cerr);
  }
  bool ReportContext(const Context& c) override { return inner_->ReportContext(c); }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (!r.error_occurred) keep(r);
    }
    inner_->ReportRuns(runs);
  }
  void Finalize() override { inner_->Finalize(); }

  static double unit_seconds(benchmark::TimeUnit u) {
    switch (u) {
      case benchmark::kNanosecond: return 1e-9;
      case benchmark::kMicrosecond: return 1e-6;
      case benchmark::kMillisecond: return 1e-3;
      case benchmark::kSecond: return 1.0;
    }
    return 1e-9;
  }

 protected:
  virtual void keep(const Run& r) = 0;

 private:
  std::unique_ptr<benchmark::BenchmarkReporter> inner_;
};

}  // namespace tonus::bench
