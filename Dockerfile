# ema: the retraining service.
# Build: docker build -t ema .
# Run:   docker run -p 8000:8000 -e EMA_API_KEY=<16+ characters> -v ema-data:/data ema
#        (or mount a key file and set EMA_API_KEY_FILE): bound beyond loopback, the service refuses to
#        start without a key.
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    EMA_HOST=0.0.0.0 \
    EMA_DATABASE=/data/ema-history.sqlite3 \
    NUMBA_CACHE_DIR=/opt/ema/numba-cache

RUN useradd --create-home --uid 10001 ema && mkdir -p /data /opt/ema/numba-cache && chown ema /data /opt/ema/numba-cache

# Dependencies first, from pyproject.toml alone, so code edits do not reinstall them.
COPY pyproject.toml /tmp/ema/
RUN python -c "import tomllib; p = tomllib.load(open('/tmp/ema/pyproject.toml', 'rb'))['project']; \
x = p['optional-dependencies']; d = p['dependencies'] + x['history'] + x['service'][1:] + x['postgres'][1:]; \
print('\n'.join(d))" > /tmp/requirements.txt \
    && pip install -r /tmp/requirements.txt

# The code, installed into site-packages; the sources are not kept beside it.
COPY ema /tmp/ema/ema
RUN pip install --no-deps /tmp/ema && rm -rf /tmp/ema  # the service's extras came with the requirements above

USER ema
WORKDIR /data
# Compile the kernels at build time, from the installed package (Numba keys its cache on the source
# path: a warm-up of another copy would leave the service to compile at every start).
RUN python -c "from ema.estimate import thread_budget; thread_budget.configure(); from ema.kinds import warm_up; warm_up()"

VOLUME ["/data"]
EXPOSE 8000
HEALTHCHECK --interval=30s --timeout=5s CMD python -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:8000/healthz', timeout=4)"
ENTRYPOINT ["ema", "serve"]
