"""The benchmarks behind ``affordplan bench``: primitives (``primitive``), plans (``plan``) and success-model
queries (``query``). They print figures; no test times them."""
