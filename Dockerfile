# ema: the retraining service. Build: docker build -t ema . ; run: docker run -p 8000:8000 ema
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    EMA_HOST=0.0.0.0 \
    EMA_DATABASE=/data/ema-history.sqlite3 \
    NUMBA_CACHE_DIR=/home/ema/.cache/numba

RUN useradd --create-home --uid 10001 ema && mkdir /data && chown ema /data
WORKDIR /app

# Dependencies first, from pyproject.toml alone, so code edits do not reinstall them.
# The CPU wheel of torch: the default index would pull a multi-GB CUDA build.
COPY pyproject.toml ./
RUN pip install --index-url https://download.pytorch.org/whl/cpu "torch==2.13.0" \
    && python -c "import tomllib; d = tomllib.load(open('pyproject.toml', 'rb'))['project']['dependencies']; \
print('\n'.join(x for x in d if not x.startswith('torch')))" > /tmp/requirements.txt \
    && pip install -r /tmp/requirements.txt

COPY sim ./sim
COPY training ./training
COPY service ./service
COPY clients ./clients
RUN pip install --no-deps .

USER ema
# Compile the kernels into the cache at build time, so the first start only loads them.
RUN python -c "from service.warmup import warm_up; warm_up()"

VOLUME ["/data"]
EXPOSE 8000
HEALTHCHECK --interval=30s --timeout=5s CMD python -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:8000/healthz', timeout=4)"
ENTRYPOINT ["ema", "serve"]
