# Google Benchmark -> benchmark::benchmark
find_package(benchmark REQUIRED)
