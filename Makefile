# Shortcuts for the README's commands (dev.py does the work and needs only Python).
.PHONY: run test
run:
	python3 dev.py run
test:
	python3 dev.py test
