import time
from selenium import webdriver
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
o=webdriver.ChromeOptions(); o.add_argument("--headless=new"); o.add_argument("--no-sandbox")
d=webdriver.Chrome(options=o)
try:
    d.get("http://127.0.0.1:22080/plcs/0/devices?from=R100&count=20"); time.sleep(1.5)
    d.find_element(By.CSS_SELECTOR,'td[data-device="R101"]').click(); time.sleep(0.3)
    inp=d.find_element(By.CSS_SELECTOR,'input[data-device="R101"]'); inp.send_keys(Keys.CONTROL,"a"); inp.send_keys("-5", Keys.ENTER); time.sleep(1)
    print("msg", d.find_element(By.ID,"message").get_attribute("class"), d.find_element(By.ID,"message").text)
    print("R101 now", d.find_element(By.CSS_SELECTOR,'td[data-device="R101"]').get_attribute("data-value"))
finally: d.quit()
