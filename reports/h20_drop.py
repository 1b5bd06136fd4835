"""docs/h20_drop.csv and docs/h20_drop.png: the console command fraccontact
run (fraccontact.run) at its defaults, which writes them."""

from fraccontact.run import main  # noqa: F401 (the report's main is the command's)
