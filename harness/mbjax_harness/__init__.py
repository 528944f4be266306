"""mbjax's harness, apart from the library: the `mbjax` command (`cli`), the tour of every scene
(`tour`), the paper reproductions (`reproduce`), the benchmark suites (`bench`), the peers they
measure against (`peers`), figures and animations (`plot`), and the progress display and worker
processes they share. It imports the library; `import mbjax` imports none of it."""
