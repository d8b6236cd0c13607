# kelp's programs, Python package and SITL bridge in one image (docs/docker.md).
#
#   docker build -t kelp .                                     # from Docker Hub's debian:bookworm
#   docker build --build-arg BASE=kelp-base:bookworm -t kelp . # any Debian 12 image (no registry:
#                                                              # scripts/docker-test makes one)
#   docker run --rm -v "$PWD/kelp-run:/out" --user "$(id -u):$(id -g)" kelp   # the demo, into ./kelp-run
#
# Two stages: `build` compiles the programs and the Python module with Debian's compilers and
# installs them into a staging prefix; the runtime stage has Python, numpy and matplotlib and the
# installed tree, no compiler and no headers.
ARG BASE=debian:bookworm

FROM ${BASE} AS build
ENV DEBIAN_FRONTEND=noninteractive
WORKDIR /src
COPY . .
# The build dependencies have one home, scripts/install-deps (the demo's packages + the Python
# package's: pybind11, Python's headers, numpy), run on the whole tree (.dockerignore keeps the
# docs, tests and build trees out of it), since a profile may install from files in it.
RUN scripts/install-deps python
# Release, no tests or benchmarks; the examples, the programs (apps/) and the Python package on
# (a missing dependency is an error). The Python package goes where Debian's python3 looks in /usr/local
# (/usr/local/lib/python3.X/dist-packages; site-packages is not on its path).
RUN cmake -S . -B build/image -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr/local \
      -DKELP_BUILD_TESTS=OFF -DKELP_BUILD_BENCHMARKS=OFF -DKELP_BUILD_EXAMPLES=ON \
      -DKELP_BUILD_APPS=ON -DKELP_BUILD_PYTHON=ON -DKELP_PYTHON_INSTALL_DIR="lib/python3.$(python3 -c \
        'import sys; print(sys.version_info.minor)')/dist-packages"
# Only what `cmake --install` installs (not the hello examples): the programs present in this
# tree and the Python module; the install below fails if any other installed target is unbuilt.
RUN targets=$(cmake --build build/image --target help | sed -n 's/^\.\.\. //p' | cut -d' ' -f1 \
      | grep -x -E 'kelp-tethered-pair|kelp-sitl|kelp-mission|kelp-sweep|kelp-replay|kelp_python|kelp_python_files|kelp_replay_.*') \
    && echo "building: " $targets \
    && cmake --build build/image -j "$(nproc)" --target $targets \
    && DESTDIR=/staging cmake --install build/image \
    && rm -rf /staging/usr/local/include /staging/usr/local/share/cmake \
    && find /staging -name '*.so' -exec strip --strip-unneeded {} + \
    && strip /staging/usr/local/bin/*

FROM ${BASE}
ENV DEBIAN_FRONTEND=noninteractive
# Runtime only: Python with numpy (the kelp package) and matplotlib (the plotting scripts).
# The programs need libstdc++ and libgcc (in every Debian base) and tinyxml2's shared library
# (kelp::sim's SDF importer; Debian ships no static one).
# python3-munkres: Debian 12's python3-fonttools (a dependency of matplotlib) needs
# "python3-scipy | python3-munkres"; left to itself apt takes SciPy, which brings Pythran, GCC,
# Boost and OpenBLAS's headers: ~900 MB and a compiler in the image.
RUN apt-get update \
    && apt-get install -y --no-install-recommends python3 python3-numpy python3-matplotlib \
       python3-munkres libstdc++6 libgcc-s1 libtinyxml2-9 \
    && apt-get clean && rm -rf /var/lib/apt/lists/* /usr/share/man/* \
    && find /usr/share/doc -type f ! -name copyright -delete
# The installed tree: /usr/local/bin/kelp-*, /usr/local/share/kelp (plot_run.py, plot_sweep.py,
# the scenarios, sitl/params and sitl/scenarios, the sweeps; share/kelp/replay when built) and
# the Python package in /usr/local/lib/python3.X/dist-packages/kelp.
COPY --from=build /staging/usr/local/ /usr/local/
# A non-root user; any --user uid works too (matplotlib's cache goes to /tmp).
RUN useradd --create-home --uid 1000 --shell /bin/bash kelp \
    && mkdir -p /out && chown kelp:kelp /out
ENV MPLCONFIGDIR=/tmp/matplotlib PYTHONDONTWRITEBYTECODE=1
USER kelp
WORKDIR /out
VOLUME /out
# kelp-sitl's default JSON ports (ArduSub -I0 and ArduRover -I1); publish them with -p .../udp
# and run it with --bind 0.0.0.0, or use --network host.
EXPOSE 9002/udp 9012/udp
# The demo: the embedded default scenario into the mounted /out.
CMD ["kelp-tethered-pair", "--out", "/out"]
